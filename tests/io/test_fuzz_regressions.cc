// Inputs the fuzzers (tests/fuzz, ci/fuzz) once crashed a parser with: each must now be a clear IoError.
#include <gtest/gtest.h>

#include <filesystem>

#include "io/error.h"
#include "io/metashape.h"

namespace litgs::io {
namespace {

const std::filesystem::path kRegressions = LITGS_FUZZ_REGRESSIONS;

TEST(FuzzRegression, MetashapeCalibrationWithAHundredDigitHeight) {
  // UBSan: float-cast-overflow converting <height>5155...52</height> to int.
  try {
    read_metashape_calibration(kRegressions / "metashape-huge-height.xml");
    FAIL() << "expected IoError";
  } catch (const IoError& e) {
    EXPECT_NE(std::string(e.what()).find("height"), std::string::npos) << e.what();
  }
}

}  // namespace
}  // namespace litgs::io
