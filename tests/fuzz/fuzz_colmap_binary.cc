// libFuzzer target: io::read_colmap_binary, one of cameras.bin / images.bin / points3D.bin fuzzed at a time.
#include "tests/fuzz/fuzz_colmap.h"

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  return litgs::fuzz::fuzz_colmap(data, size, true,
                                  [](const auto& dir) { litgs::io::read_colmap_binary(dir); });
}
