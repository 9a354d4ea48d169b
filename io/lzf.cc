#include "io/lzf.h"

namespace litgs::io {

std::string lzf_decompress(const unsigned char* in, size_t in_size, unsigned char* out, size_t out_size) {
  size_t ip = 0, op = 0;
  while (ip < in_size) {
    const unsigned ctrl = in[ip++];
    if (ctrl < 32) {  // literal run of ctrl + 1 bytes
      const size_t len = ctrl + 1;
      if (ip + len > in_size) return "literal run past the end of the compressed data";
      if (op + len > out_size) return "literal run past the end of the output";
      for (size_t i = 0; i < len; ++i) out[op++] = in[ip++];
    } else {  // back reference
      size_t len = ctrl >> 5;
      if (len == 7) {
        if (ip >= in_size) return "back reference length past the end of the compressed data";
        len += in[ip++];
      }
      len += 2;
      if (ip >= in_size) return "back reference offset past the end of the compressed data";
      const size_t back = ((ctrl & 0x1fu) << 8) + in[ip++] + 1;
      if (back > op) return "back reference before the start of the output";
      if (op + len > out_size) return "back reference past the end of the output";
      for (size_t i = 0; i < len; ++i, ++op) out[op] = out[op - back];  // byte by byte: runs may overlap
    }
  }
  if (op != out_size)
    return "decompressed " + std::to_string(op) + " bytes, the header says " + std::to_string(out_size);
  return {};
}

}  // namespace litgs::io
