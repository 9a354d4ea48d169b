#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>

#include "io/file_bytes.h"
#include "io/ply_points.h"
#include "tests/io/io_test.h"

namespace litgs::io {
namespace {

class PlyTest : public testing::TempDirTest {};

TEST_F(PlyTest, ReadsBinaryLidarScan) {
  const PointCloud cloud = read_ply_points(testing::data_dir() / "small-gicp-pair/source.ply");
  ASSERT_EQ(cloud.size(), 69792u);
  ASSERT_EQ(cloud.intensity.size(), 69792u);  // CloudCompare's scalar_intensity
  // First and last vertex, decoded independently with Python's struct module.
  EXPECT_EQ(cloud.positions.front(),
            Eigen::Vector3d(0.004045109264552593, 2.5751945972442627, -1.5272173881530762));
  EXPECT_EQ(cloud.intensity.front(), 70.0f);
  EXPECT_EQ(cloud.positions.back(),
            Eigen::Vector3d(-0.004093721974641085, 1.804250717163086, 0.3399392366409302));
  EXPECT_EQ(cloud.intensity.back(), 36.0f);
  float lo = 1e9f, hi = -1e9f;
  for (float v : cloud.intensity) lo = std::min(lo, v), hi = std::max(hi, v);
  EXPECT_EQ(lo, 0.0f);
  EXPECT_EQ(hi, 187.0f);
}

TEST_F(PlyTest, ReadsAsciiColmapPoints) {
  const PointCloud cloud =
      read_ply_points(testing::data_dir() / "thermitage-dunr/colmap-triangulated-points.ply");
  ASSERT_EQ(cloud.size(), 3988u);
  EXPECT_EQ(cloud.positions.front(), Eigen::Vector3d(1000.8843, 1009.5630, 100.5749));
  EXPECT_EQ(cloud.intensity.front(), 62.0f);
  ASSERT_NE(cloud.field("error_px"), nullptr);
  ASSERT_NE(cloud.field("track_length"), nullptr);
  EXPECT_DOUBLE_EQ(cloud.field("error_px")->values.front(), 2.254);
  EXPECT_EQ(cloud.field("track_length")->values.back(), 5.0);
  EXPECT_EQ(cloud.positions.back(), Eigen::Vector3d(996.7753, 1009.3601, 102.7031));
  // Facade points: Northing near the control points' 1008.9..1009.7 m plane.
  std::vector<double> y;
  for (const auto& p : cloud.positions) y.push_back(p.y());
  std::nth_element(y.begin(), y.begin() + y.size() / 2, y.end());
  EXPECT_NEAR(y[y.size() / 2], 1009.4, 0.5);
}

TEST_F(PlyTest, TruncatedBinaryNamesTheEntry) {
  const std::string bytes = read_file_bytes(testing::data_dir() / "small-gicp-pair/source.ply");
  const auto path = write_text("cut.ply", bytes.substr(0, bytes.size() - 100));
  testing::expect_io_error([&] { read_ply_points(path); },
                           {"cut.ply", "truncated", "element 'vertex' entry 69785"});
}

TEST_F(PlyTest, CorruptFilesHaveClearErrors) {
  testing::expect_io_error([&] { read_ply_points(write_text("a.ply", "plx\n")); }, {"a.ply:1:", "not a PLY"});
  const std::string head = "ply\nformat ascii 1.0\nelement vertex 2\nproperty float x\nproperty float y\n";
  testing::expect_io_error([&] { read_ply_points(write_text("b.ply", head + "end_header\n1 2\n3 4\n")); },
                           {"b.ply:6:", "lacks one of x y z"});
  const std::string xyz = head + "property float z\nend_header\n";
  testing::expect_io_error([&] { read_ply_points(write_text("c.ply", xyz + "1 2 3\n4 5\n")); },
                           {"c.ply:9:", "too few values"});
  testing::expect_io_error([&] { read_ply_points(write_text("d.ply", xyz + "1 2 3\n4 nan 6\n")); },
                           {"d.ply:9:", "non-finite"});
  testing::expect_io_error([&] { read_ply_points(write_text("e.ply", xyz + "1 2 3\n")); },
                           {"e.ply:9:", "truncated", "1 present"});
  testing::expect_io_error(
      [&] {
        read_ply_points(write_text("f.ply", "ply\nformat ascii 1.0\nelement vertex 1\nproperty half x\n"));
      },
      {"f.ply:4:", "unknown property type 'half'"});
}

TEST_F(PlyTest, ForgedCountsFailWithoutHugeAllocations) {
  const std::string head =
      "ply\nformat binary_little_endian 1.0\nelement vertex 1099511627775\nproperty float x\n"
      "property float y\nproperty float z\nend_header\n";
  testing::expect_io_error([&] { read_ply_points(write_text("v.ply", head + "0123456789ab")); },
                           {"v.ply", "truncated", "entry 1 of 1099511627775"});
  const std::string faces =
      "ply\nformat binary_little_endian 1.0\nelement face 1\n"
      "property list uint int vertex_indices\nelement vertex 0\nproperty float x\n"
      "property float y\nproperty float z\nend_header\n";
  testing::expect_io_error([&] { read_ply_points(write_text("f.ply", faces + std::string(4, '\xff'))); },
                           {"f.ply", "list length 4294967295 is impossible"});
}

TEST_F(PlyTest, SkipsFacesAndReadsBigEndian) {
  std::string s =
      "ply\nformat binary_big_endian 1.0\nelement face 1\nproperty list uchar int vertex_indices\n"
      "element vertex 1\nproperty double x\nproperty double y\nproperty double z\nend_header\n";
  s += std::string("\x03\x00\x00\x00\x01\x00\x00\x00\x02\x00\x00\x00\x03", 13);
  const double xyz[3] = {1.5, -2.0, 1000.25};
  for (double v : xyz) {
    unsigned char b[8];
    std::memcpy(b, &v, 8);
    for (int i = 7; i >= 0; --i) s.push_back(static_cast<char>(b[i]));
  }
  const PointCloud cloud = read_ply_points(write_text("be.ply", s));
  ASSERT_EQ(cloud.size(), 1u);
  EXPECT_EQ(cloud.positions[0], Eigen::Vector3d(1.5, -2.0, 1000.25));
}

}  // namespace
}  // namespace litgs::io
