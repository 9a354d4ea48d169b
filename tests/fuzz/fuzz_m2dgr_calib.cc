// libFuzzer target: io::read_m2dgr_camera (M2DGR calibration_results.txt, the Cam-thermal block).
#include "io/m2dgr_calib.h"
#include "tests/fuzz/fuzz_util.h"

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  const auto path = litgs::fuzz::write_temp("calibration_results.txt", data, size);
  return litgs::fuzz::expect_only_io_error([&] { litgs::io::read_m2dgr_camera(path); });
}
