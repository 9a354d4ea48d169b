// Inputs the fuzzers (tests/fuzz, ci/fuzz) once crashed a parser with: each must now be a clear IoError.
#include <gtest/gtest.h>

#include <filesystem>

#include "io/error.h"
#include "io/image.h"
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

TEST(FuzzRegression, TiffDeclaringGigabytesInATinyFile) {
  // libFuzzer out-of-memory: 214 bytes declaring 9477x65277 pixels of three 16-bit samples, deflated; the
  // reader allocated the 3.7 GB image before decoding the first row.
  try {
    read_tiff(kRegressions / "tiff-declares-gigabytes.tiff");
    FAIL() << "expected IoError";
  } catch (const IoError& e) {
    EXPECT_NE(std::string(e.what()).find("strips hold"), std::string::npos) << e.what();
  }
}

TEST(FuzzRegression, TiffWhoseStripByteCountsClaimMoreThanTheFileHolds) {
  // libFuzzer out-of-memory (malloc of 1.26 GB): 200 bytes, deflated, whose StripByteCounts claims a 1.1 MB
  // strip, which at 4096-fold expansion passed the size check.
  try {
    read_tiff(kRegressions / "tiff-strip-counts-beyond-the-file.tiff");
    FAIL() << "expected IoError";
  } catch (const IoError& e) {
    EXPECT_NE(std::string(e.what()).find("strips hold 200 bytes"), std::string::npos) << e.what();
  }
}

}  // namespace
}  // namespace litgs::io
