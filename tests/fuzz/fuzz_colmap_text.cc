// libFuzzer target: io::read_colmap_text, one of cameras.txt / images.txt / points3D.txt fuzzed at a time.
#include "tests/fuzz/fuzz_colmap.h"

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  return litgs::fuzz::fuzz_colmap(data, size, false,
                                  [](const auto& dir) { litgs::io::read_colmap_text(dir); });
}
