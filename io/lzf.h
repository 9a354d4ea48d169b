// LZF decompression (the codec of PCD "binary_compressed"), written from the format description: a stream of
// literal runs (control byte < 32: copy control+1 bytes) and back references (length in the top 3 bits,
// 7 meaning "add the next byte", offset in the low 5 bits and the next byte).
#pragma once

#include <cstddef>
#include <string>

namespace litgs::io {

// Decompresses exactly `out_size` bytes into out. Returns an empty string on success, else the problem
// (truncated input, a reference before the start, output overrun, size mismatch).
std::string lzf_decompress(const unsigned char* in, size_t in_size, unsigned char* out, size_t out_size);

}  // namespace litgs::io
