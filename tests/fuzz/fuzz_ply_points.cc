// libFuzzer target: io::read_ply_points (PLY point clouds, ascii and binary).
#include "io/ply_points.h"
#include "tests/fuzz/fuzz_util.h"

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  const auto path = litgs::fuzz::write_temp("cloud.ply", data, size);
  return litgs::fuzz::expect_only_io_error([&] { litgs::io::read_ply_points(path); });
}
