#include <gtest/gtest.h>

#include <cstring>

#include "io/file_bytes.h"
#include "io/pcd.h"
#include "tests/io/io_test.h"

namespace litgs::io {
namespace {

class PcdTest : public testing::TempDirTest {};

PointCloud sample_cloud() {
  PointCloud c;
  c.positions = {{1.5, -2.25, 3.0}, {1000.125, 0.5, -7.75}, {0, 0, 0}};
  c.intensity = {10.f, 20.5f, 0.f};
  c.normals = {{0, 0, 1}, {1, 0, 0}, {0.6f, 0.8f, 0}};
  c.extra.push_back({"ring", {1, 2, 3}});
  return c;
}

void expect_same(const PointCloud& a, const PointCloud& b) {
  ASSERT_EQ(a.size(), b.size());
  EXPECT_EQ(a.positions, b.positions);
  EXPECT_EQ(a.intensity, b.intensity);
  EXPECT_EQ(a.normals, b.normals);
  ASSERT_EQ(a.extra.size(), b.extra.size());
  for (size_t i = 0; i < a.extra.size(); ++i) {
    EXPECT_EQ(a.extra[i].name, b.extra[i].name);
    EXPECT_EQ(a.extra[i].values, b.extra[i].values);
  }
}

TEST_F(PcdTest, BinaryRoundTrip) {
  const PointCloud c = sample_cloud();  // values exact in float32
  write_pcd(dir_ / "f.pcd", c);
  expect_same(read_pcd(dir_ / "f.pcd"), c);
  PointCloud d = c;
  d.positions[1] = {1000.123456789012, 1009.6704, 104.1154};  // needs float64
  write_pcd(dir_ / "d.pcd", d, {.double_positions = true});
  expect_same(read_pcd(dir_ / "d.pcd"), d);
}

TEST_F(PcdTest, ReadsAsciiWithPadAndDescriptorFields) {
  const auto path = write_text("a.pcd",
                               "# .PCD v0.7\nVERSION 0.7\nFIELDS x y z _ fpfh intensity\nSIZE 4 4 4 1 4 4\n"
                               "TYPE F F F U F F\nCOUNT 1 1 1 1 3 1\nWIDTH 2\nHEIGHT 1\n"
                               "VIEWPOINT 0 0 0 1 0 0 0\nPOINTS 2\nDATA ascii\n"
                               "1 2 3 0 9 9 9 5\n\n-1 -2 -3.5 0 9 9 9 6\n");
  const PointCloud c = read_pcd(path);
  ASSERT_EQ(c.size(), 2u);
  EXPECT_EQ(c.positions[1], Eigen::Vector3d(-1, -2, -3.5));
  EXPECT_EQ(c.intensity, (std::vector<float>{5, 6}));
  EXPECT_TRUE(c.extra.empty());
}

// A hand-made binary_compressed file: two points x y z (float), fields stored one after the other
// (x0 x1 y0 y1 z0 z1), LZF-coded as one literal run of 8 bytes then a back reference that repeats them twice
// (so y and z equal x): exercises literals, an overlapping back reference and the SoA layout.
TEST_F(PcdTest, ReadsBinaryCompressed) {
  const float xs[2] = {1.25f, -3.5f};
  std::string lzf;
  lzf.push_back(7);  // literal run of 8 bytes
  lzf.append(reinterpret_cast<const char*>(xs), 8);
  // back reference: length 16 = 7 + 7 + 2 (top bits 7, extra byte 7), offset 8 = 7 + 1
  lzf.push_back(static_cast<char>((7 << 5) | 0));
  lzf.push_back(7);
  lzf.push_back(7);
  std::string s =
      "VERSION 0.7\nFIELDS x y z\nSIZE 4 4 4\nTYPE F F F\nCOUNT 1 1 1\nWIDTH 2\nHEIGHT 1\nPOINTS 2\n"
      "DATA binary_compressed\n";
  const uint32_t sizes[2] = {static_cast<uint32_t>(lzf.size()), 24};
  s.append(reinterpret_cast<const char*>(sizes), 8);
  s += lzf;
  const PointCloud c = read_pcd(write_text("c.pcd", s));
  ASSERT_EQ(c.size(), 2u);
  EXPECT_EQ(c.positions[0], Eigen::Vector3d(1.25, 1.25, 1.25));
  EXPECT_EQ(c.positions[1], Eigen::Vector3d(-3.5, -3.5, -3.5));
  // The same stream with the reference pointing before the start of the output.
  s[s.size() - 1] = 20;
  testing::expect_io_error([&] { read_pcd(write_text("bad.pcd", s)); },
                           {"bad.pcd", "corrupt LZF", "before the start"});
}

TEST_F(PcdTest, TruncatedBinaryIsAnError) {
  write_pcd(dir_ / "full.pcd", sample_cloud());
  const std::string bytes = read_file_bytes(dir_ / "full.pcd");
  const auto path = write_text("cut.pcd", bytes.substr(0, bytes.size() - 5));
  testing::expect_io_error([&] { read_pcd(path); }, {"cut.pcd", "truncated", "3 points of 36 bytes"});
}

TEST_F(PcdTest, HeaderErrorsNameTheLine) {
  testing::expect_io_error(
      [&] {
        read_pcd(write_text("s.pcd",
                            "FIELDS x y z\nSIZE 4 4\nTYPE F F F\nWIDTH 1\nHEIGHT 1\nDATA ascii\n1 2 3\n"));
      },
      {"s.pcd:2:", "SIZE has 2 entries for 3 FIELDS"});
  testing::expect_io_error(
      [&] {
        read_pcd(write_text(
            "w.pcd", "FIELDS x y z\nSIZE 4 4 4\nTYPE F F F\nWIDTH 2\nHEIGHT 1\nPOINTS 3\nDATA ascii\n"));
      },
      {"w.pcd:7:", "WIDTH*HEIGHT = 2 but POINTS = 3"});
  testing::expect_io_error(
      [&] {
        read_pcd(write_text("k.pcd", "FIELDS x y z\nSIZE 4 4 4\nTYPE F F F\nWIDTH 1\nHEIGHT 1\nDATA lzma\n"));
      },
      {"k.pcd:6:", "unknown DATA kind 'lzma'"});
  testing::expect_io_error([&] { read_pcd(write_text("n.pcd", "FIELDS x y z\n")); },
                           {"n.pcd:2:", "before a DATA line"});
  testing::expect_io_error([&] { read_pcd(dir_ / "missing.pcd"); }, {"missing.pcd", "does not exist"});
}

TEST_F(PcdTest, ForgedPointCountsFailWithoutHugeAllocations) {
  const std::string head = "FIELDS x y z\nSIZE 8 8 8\nTYPE F F F\nWIDTH 1099511627775\nHEIGHT 1\n";
  testing::expect_io_error([&] { read_pcd(write_text("b.pcd", head + "DATA binary\n0123456789")); },
                           {"b.pcd", "truncated", "1099511627775 points"});
  testing::expect_io_error([&] { read_pcd(write_text("a.pcd", head + "DATA ascii\n1 2 3\n")); },
                           {"a.pcd:8:", "truncated", "1 present"});
  testing::expect_io_error(
      [&] { read_pcd(write_text("c.pcd", head + "DATA binary_compressed\n" + std::string(8, '\xff'))); },
      {"c.pcd", "uncompressed size"});
}

TEST_F(PcdTest, AsciiValueErrorsNameTheLine) {
  const std::string head = "FIELDS x y z\nSIZE 4 4 4\nTYPE F F F\nWIDTH 2\nHEIGHT 1\nDATA ascii\n";
  testing::expect_io_error([&] { read_pcd(write_text("t.pcd", head + "1 2 3\n4 5\n")); },
                           {"t.pcd:8:", "expected 3 values, got 2"});
  testing::expect_io_error([&] { read_pcd(write_text("u.pcd", head + "1 2 3\n")); },
                           {"u.pcd:8:", "truncated", "1 present"});
  const auto nan_path = write_text("nan.pcd", head + "1 2 3\nnan nan nan\n");
  testing::expect_io_error([&] { read_pcd(nan_path); }, {"nan.pcd:8:", "non-finite position"});
  const PointCloud kept = read_pcd(nan_path, {.drop_nonfinite_points = true});
  ASSERT_EQ(kept.size(), 1u);
  EXPECT_EQ(kept.positions[0], Eigen::Vector3d(1, 2, 3));
}

}  // namespace
}  // namespace litgs::io
