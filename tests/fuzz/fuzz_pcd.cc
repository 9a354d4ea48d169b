// libFuzzer target: io::read_pcd (PCD point clouds: ascii, binary, binary_compressed).
#include "io/pcd.h"
#include "tests/fuzz/fuzz_util.h"

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  const auto path = litgs::fuzz::write_temp("cloud.pcd", data, size);
  return litgs::fuzz::expect_only_io_error([&] { litgs::io::read_pcd(path); });
}
