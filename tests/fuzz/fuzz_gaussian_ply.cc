// libFuzzer target: io::read_gaussian_ply (3DGS PLY models).
#include "io/gaussian_ply.h"
#include "tests/fuzz/fuzz_util.h"

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  const auto path = litgs::fuzz::write_temp("model.ply", data, size);
  return litgs::fuzz::expect_only_io_error([&] { litgs::io::read_gaussian_ply(path); });
}
