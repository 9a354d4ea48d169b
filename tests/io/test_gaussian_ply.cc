// The standard 3DGS PLY: round trips of 1- and 3-channel models at every SH degree, the Inria property
// layout, and clear errors for malformed files.
#include <gtest/gtest.h>

#include <fstream>
#include <random>

#include "io/error.h"
#include "io/gaussian_ply.h"
#include "io/ply_points.h"
#include "io_test.h"

namespace litgs::io {
namespace {

kernels::GaussianModel random_model(size_t n, uint32_t channels, uint32_t degree) {
  kernels::GaussianModel m;
  m.channels = channels;
  m.sh_degree = degree;
  m.resize(n);
  std::mt19937 rng(channels * 10 + degree);
  std::uniform_real_distribution<float> u(-2.0f, 2.0f);
  for (auto* v : {&m.means, &m.log_scales, &m.quats, &m.opacity_logits, &m.sh})
    for (auto& x : *v) x = u(rng);
  return m;
}

class GaussianPlyTest : public testing::TempDirTest {};

TEST_F(GaussianPlyTest, RoundTripsEveryDegreeAndChannelCount) {
  for (uint32_t channels : {1u, 3u})
    for (uint32_t degree = 0; degree <= 3; ++degree) {
      const auto m = random_model(17, channels, degree);
      const auto path = dir_ / "model.ply";
      write_gaussian_ply(path, m);
      const auto r = read_gaussian_ply(path);
      EXPECT_EQ(r.channels, channels);
      EXPECT_EQ(r.sh_degree, degree);
      EXPECT_EQ(r.means, m.means);
      EXPECT_EQ(r.log_scales, m.log_scales);
      EXPECT_EQ(r.quats, m.quats);
      EXPECT_EQ(r.opacity_logits, m.opacity_logits);
      EXPECT_EQ(r.sh, m.sh) << channels << " channels, degree " << degree;
    }
}

TEST_F(GaussianPlyTest, InriaLayoutChannelMajorRest) {
  // Degree 1, 3 channels: f_rest_0..2 are channel 0's three coefficients, f_rest_3..5 channel 1's.
  auto m = random_model(1, 3, 1);
  for (uint32_t k = 0; k < 4; ++k)
    for (uint32_t c = 0; c < 3; ++c) m.sh[k * 3 + c] = static_cast<float>(10 * c + k);
  const auto path = dir_ / "layout.ply";
  write_gaussian_ply(path, m);
  const auto cloud = read_ply_points(path);
  EXPECT_EQ(cloud.field("f_dc_1")->values[0], 10.0);
  EXPECT_EQ(cloud.field("f_rest_0")->values[0], 1.0);   // channel 0, k = 1
  EXPECT_EQ(cloud.field("f_rest_2")->values[0], 3.0);   // channel 0, k = 3
  EXPECT_EQ(cloud.field("f_rest_3")->values[0], 11.0);  // channel 1, k = 1
  EXPECT_EQ(cloud.field("opacity")->values[0], m.opacity_logits[0]);
  EXPECT_EQ(cloud.field("rot_0")->values[0], m.quats[0]);
}

TEST_F(GaussianPlyTest, OneChannelIsGrayForViewers) {
  const auto m = random_model(3, 1, 2);
  const auto path = dir_ / "gray.ply";
  write_gaussian_ply(path, m);
  const auto cloud = read_ply_points(path);
  for (size_t i = 0; i < 3; ++i) {
    EXPECT_EQ(cloud.field("f_dc_0")->values[i], cloud.field("f_dc_1")->values[i]);
    EXPECT_EQ(cloud.field("f_dc_0")->values[i], cloud.field("f_dc_2")->values[i]);
  }
}

TEST_F(GaussianPlyTest, MissingPropertyIsNamed) {
  const auto path = write_text("bad.ply",
                               "ply\nformat ascii 1.0\nelement vertex 1\nproperty float x\nproperty float y\n"
                               "property float z\nproperty float f_dc_0\nend_header\n0 0 0 1\n");
  try {
    read_gaussian_ply(path);
    FAIL();
  } catch (const IoError& e) {
    EXPECT_NE(std::string(e.what()).find("bad.ply"), std::string::npos) << e.what();
  }
}

TEST_F(GaussianPlyTest, TruncatedFileIsAnError) {
  const auto m = random_model(50, 3, 3);
  const auto path = dir_ / "full.ply";
  write_gaussian_ply(path, m);
  const auto size = std::filesystem::file_size(path);
  std::filesystem::resize_file(path, size - 100);
  EXPECT_THROW(read_gaussian_ply(path), IoError);
}

TEST_F(GaussianPlyTest, BadRestCountIsAnError) {
  std::string header = "ply\nformat ascii 1.0\nelement vertex 1\n";
  for (const char* p : {"x", "y", "z", "f_dc_0", "f_dc_1", "f_dc_2", "f_rest_0", "f_rest_1", "opacity",
                        "scale_0", "scale_1", "scale_2", "rot_0", "rot_1", "rot_2", "rot_3"})
    header += std::string("property float ") + p + "\n";
  const auto path = write_text("rest.ply", header + "end_header\n0 0 0 0 0 0 0 0 0 0 0 0 1 0 0 0\n");
  EXPECT_THROW(read_gaussian_ply(path), IoError);
}

TEST_F(GaussianPlyTest, FailedWriteKeepsTheOldFile) {
  const auto path = dir_ / "keep.ply";
  write_gaussian_ply(path, random_model(5, 3, 0));
  const auto before = std::filesystem::file_size(path);
  auto bad = random_model(5, 2, 0);  // 2 channels cannot be written
  EXPECT_THROW(write_gaussian_ply(path, bad), std::invalid_argument);
  EXPECT_EQ(std::filesystem::file_size(path), before);
  EXPECT_NO_THROW(read_gaussian_ply(path));
}

}  // namespace
}  // namespace litgs::io
