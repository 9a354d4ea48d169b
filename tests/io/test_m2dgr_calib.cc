#include <gtest/gtest.h>

#include "io/m2dgr_calib.h"
#include "tests/io/io_test.h"

namespace litgs::io {
namespace {

class M2dgrCalibTest : public testing::TempDirTest {};

TEST_F(M2dgrCalibTest, ReadsTheThermalBlockOfTheRealFile) {
  const M2dgrCamera c = read_m2dgr_camera(testing::data_dir() / "m2dgr/calibration_results.txt");
  EXPECT_EQ(c.block, "Cam-thermal");
  ASSERT_TRUE(c.has_intrinsics);
  EXPECT_DOUBLE_EQ(c.fx, 435.836180277211);
  EXPECT_DOUBLE_EQ(c.fy, 435.909430631362);
  EXPECT_DOUBLE_EQ(c.cx, 324.452753232850);
  EXPECT_DOUBLE_EQ(c.cy, 255.554320082190);
  EXPECT_EQ(c.distortion, (std::vector<double>{-0.436107594318055, 0.166413618922992, 0, 0}));
  EXPECT_EQ(c.width, 640);
  EXPECT_EQ(c.height, 512);
  ASSERT_TRUE(c.has_extrinsic);
  Eigen::Matrix4d T;
  T << 0, 0, 1, 0.30456, -1, 0, 0, 0.17065, 0, -1, 0, 0.65376, 0, 0, 0, 1;
  EXPECT_EQ(c.T_lidar_cam, T);
  // "To LIDAR": the camera's optical axis (z) is the LiDAR's forward axis (x).
  EXPECT_EQ((c.T_lidar_cam.topLeftCorner<3, 3>() * Eigen::Vector3d::UnitZ()), Eigen::Vector3d::UnitX());
  ASSERT_EQ(c.notes.size(), 2u);  // the full-width comma and the transposed matrix
}

TEST_F(M2dgrCalibTest, ReadsAnUprightBlock) {
  const M2dgrCamera c =
      read_m2dgr_camera(testing::data_dir() / "m2dgr/calibration_results.txt", "Cam-left 8823");
  EXPECT_DOUBLE_EQ(c.fx, 540.645056202188);
  EXPECT_DOUBLE_EQ(c.cx, 626.4125666883942);
  EXPECT_EQ(c.width, 1280);
  EXPECT_TRUE(c.notes.empty());
}

TEST_F(M2dgrCalibTest, TheStrayBracketOfTheRealFileNamesItsLine) {
  // "%% Cam-midleft8830" has "data: [-0.0615..., -0.0086...], -0.0098..., 0.0048...]" on line 76.
  testing::expect_io_error(
      [&] { read_m2dgr_camera(testing::data_dir() / "m2dgr/calibration_results.txt", "Cam-midleft8830"); },
      {"calibration_results.txt:76:", "stray ']'"});
}

TEST_F(M2dgrCalibTest, MalformedBlocksNameTheLine) {
  const auto path = write_text("c.txt",
                               "%% Cam-x\n% Intrinsic\ndata: [1, 0, 5,\n 0, 1, 6,\n 0, 2, 1]\n%% Cam-y\n"
                               "% Image Size\ndata: [640]\n%% Cam-z\n% Distortion\ndata: [1, 2, nan, 4]\n");
  testing::expect_io_error([&] { read_m2dgr_camera(path, "Cam-x"); }, {"c.txt:3:", "neither"});
  testing::expect_io_error([&] { read_m2dgr_camera(path, "Cam-y"); },
                           {"c.txt:8:", "expected 2 numbers, got: 1"});
  testing::expect_io_error([&] { read_m2dgr_camera(path, "Cam-z"); }, {"c.txt:11:", "non-finite"});
  testing::expect_io_error([&] { read_m2dgr_camera(path, "Cam-w"); }, {"c.txt", "no block '%% Cam-w'"});
}

}  // namespace
}  // namespace litgs::io
