// Inputs the fuzzers (tests/fuzz, ci/fuzz) once crashed a parser with: each must now be a clear IoError.
#include <gtest/gtest.h>

#include <filesystem>

#include "io/error.h"
#include "io/image.h"
#include "io/metashape.h"
#include "io/ros_bag.h"
#include "tests/io/io_test.h"

namespace litgs::io {
namespace {

const std::filesystem::path kRegressions = LITGS_FUZZ_REGRESSIONS;

TEST(FuzzRegression, MetashapeCalibrationWithAHundredDigitHeight) {
  // UBSan: float-cast-overflow converting <height>5155...52</height> to int.
  testing::expect_io_error([] { read_metashape_calibration(kRegressions / "metashape-huge-height.xml"); },
                           {"height"});
}

TEST(FuzzRegression, TiffDeclaringGigabytesInATinyFile) {
  // libFuzzer out-of-memory: 214 bytes declaring 9477x65277 pixels of three 16-bit samples, deflated; the
  // reader allocated the 3.7 GB image before decoding the first row.
  testing::expect_io_error([] { read_tiff(kRegressions / "tiff-declares-gigabytes.tiff"); }, {"strips hold"});
}

TEST(FuzzRegression, TiffWhoseStripByteCountsClaimMoreThanTheFileHolds) {
  // libFuzzer out-of-memory (malloc of 1.26 GB): 200 bytes, deflated, whose StripByteCounts claims a 1.1 MB
  // strip, which at 4096-fold expansion passed the size check.
  testing::expect_io_error([] { read_tiff(kRegressions / "tiff-strip-counts-beyond-the-file.tiff"); },
                           {"strips hold 200 bytes, the whole file"});
}

TEST(FuzzRegression, RosBagReindexedWhereAChunkFailsPartWay) {
  // UBSan (ci/fuzz, the reindex path): a chunk whose records stop parsing part-way left index entries
  // pointing at a chunk that was never kept, read out of bounds when their messages were fetched. Entries
  // are now kept only for chunks that parse whole: this bag reads to its last good chunk, or fails clearly.
  RosBagTopics topics{"/thermal", "/lidar", "/imu", "/odom"};
  size_t messages = 0;
  RosBagHandlers h;
  h.thermal = [&](double, Image) { ++messages; };
  h.lidar = [&](double, PointCloud) { ++messages; };
  h.imu = [&](const ImuSample&) { ++messages; };
  h.odom = [&](const TumPose&) { ++messages; };
  const auto bag = kRegressions / "ros-bag-reindex-chunk-failing-part-way.bag";
  try {
    const RosBagCounts n = read_ros_bag(bag, topics, h, {.reindex = true});
    EXPECT_TRUE(n.recovery.used);
    EXPECT_EQ(messages, n.thermal + n.lidar + n.imu + n.odom);
  } catch (const IoError& e) {
    EXPECT_NE(std::string(e.what()).find(bag.filename().string()), std::string::npos) << e.what();
  }
}

}  // namespace
}  // namespace litgs::io
