// libFuzzer target: io::read_metashape_xml (camera XML) and io::read_metashape_calibration (sensor XML) on
// the same bytes.
#include "io/metashape.h"
#include "tests/fuzz/fuzz_util.h"

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  const auto path = litgs::fuzz::write_temp("cameras.xml", data, size);
  litgs::fuzz::expect_only_io_error([&] { litgs::io::read_metashape_xml(path); });
  return litgs::fuzz::expect_only_io_error([&] { litgs::io::read_metashape_calibration(path); });
}
