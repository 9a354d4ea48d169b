#include <gtest/gtest.h>

#include "io/tum.h"
#include "tests/io/io_test.h"

namespace litgs::io {
namespace {

class TumTest : public testing::TempDirTest {};

TEST_F(TumTest, ReadsM2dgrTrackerGroundTruthAsTranslationOnly) {
  const auto path = testing::data_dir() / "m2dgr/hall_03.txt";
  const auto poses = read_tum(path);
  ASSERT_EQ(poses.size(), 1213u);
  for (const auto& p : poses) EXPECT_FALSE(p.has_rotation);
  // First line: 1628410457.030000210 -10.2993 -7.0555 -4.9342 0 0 0 0
  EXPECT_DOUBLE_EQ(poses[0].t_s, 1628410457.030000210);
  EXPECT_EQ(poses[0].p_world, Eigen::Vector3d(-10.2993, -7.0555, -4.9342));
  EXPECT_DOUBLE_EQ(poses[1].t_s, 1628410457.180000067);
}

TEST_F(TumTest, RoundTripIsExact) {
  std::vector<TumPose> poses(3);
  poses[0].t_s = 0.1;
  poses[0].p_world = {1.0 / 3.0, -2.5, 1e-9};
  poses[0].q_world_body = Eigen::Quaterniond(0.9, 0.1, -0.3, 0.2).normalized();
  poses[1].t_s = 0.2;
  poses[1].has_rotation = false;
  poses[1].p_world = {1000.123456789, 2, 3};
  poses[2].t_s = 1628410457.03;
  const auto path = dir_ / "poses.txt";
  write_tum(path, poses);
  const auto back = read_tum(path);
  ASSERT_EQ(back.size(), 3u);
  for (size_t i = 0; i < 3; ++i) {
    EXPECT_EQ(back[i].t_s, poses[i].t_s);
    EXPECT_EQ(back[i].p_world, poses[i].p_world);
    EXPECT_EQ(back[i].has_rotation, poses[i].has_rotation);
    if (poses[i].has_rotation) {
      EXPECT_LT((back[i].q_world_body.coeffs() - poses[i].q_world_body.coeffs()).norm(), 1e-15);
    }
  }
}

TEST_F(TumTest, WrongFieldCountNamesFileAndLine) {
  const auto path = write_text("bad.txt", "# header\n0 0 0 0 0 0 0 1\n1 0 0 0 0 0 1\n");
  testing::expect_io_error([&] { read_tum(path); }, {"bad.txt:3:", "expected 8 fields", "got 7"});
}

TEST_F(TumTest, NanPoseIsRejected) {
  const auto path = write_text("nan.txt", "0 0 0 0 0 0 0 1\n1 nan 0 0 0 0 0 1\n");
  testing::expect_io_error([&] { read_tum(path); }, {"nan.txt:2:", "x", "non-finite"});
}

TEST_F(TumTest, NonMonotonicTimestampsAreRejected) {
  const auto path = write_text("order.txt", "0 0 0 0 0 0 0 1\n2 0 0 0 0 0 0 1\n2 0 0 0 0 0 0 1\n");
  testing::expect_io_error([&] { read_tum(path); }, {"order.txt:3:", "not greater than the previous 2"});
}

TEST_F(TumTest, BadQuaternionNormIsRejected) {
  const auto path = write_text("q.txt", "0 0 0 0 0 0 0 2\n");
  testing::expect_io_error([&] { read_tum(path); }, {"q.txt:1:", "quaternion norm is 2"});
}

TEST_F(TumTest, MissingFileIsNamed) {
  testing::expect_io_error([&] { read_tum(dir_ / "none.txt"); }, {"none.txt", "does not exist"});
}

}  // namespace
}  // namespace litgs::io
