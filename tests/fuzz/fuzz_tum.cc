// libFuzzer target: io::read_tum (TUM trajectories).
#include "io/tum.h"
#include "tests/fuzz/fuzz_util.h"

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  const auto path = litgs::fuzz::write_temp("poses.txt", data, size);
  return litgs::fuzz::expect_only_io_error([&] { litgs::io::read_tum(path); });
}
