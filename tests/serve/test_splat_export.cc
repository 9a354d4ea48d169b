// `export splat`: the 32-byte layout field by field, its order, palettes, refusals, and the CLI end to end.
#include <gtest/gtest.h>
#include <unistd.h>

#include <cmath>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <iterator>

#include "engine_cli.h"
#include "io/gaussian_ply.h"
#include "io/splat_export.h"

namespace litgs::io {
namespace {

namespace fs = std::filesystem;

// Two one-channel Gaussians: the second is larger and more opaque, so it comes first.
kernels::GaussianModel two_gaussians(uint32_t channels) {
  kernels::GaussianModel m;
  m.channels = channels;
  m.sh_degree = 1;
  m.resize(2);
  const float means[] = {1, 2, 3, -4, 5.5f, 6};
  const float log_scales[] = {-3, -3, -3, -1, -2, -0.5f};
  const float quats[] = {2, 0, 0, 0, 0.5f, 0.5f, -0.5f, 0.5f};
  std::copy(std::begin(means), std::end(means), m.means.begin());
  std::copy(std::begin(log_scales), std::end(log_scales), m.log_scales.begin());
  std::copy(std::begin(quats), std::end(quats), m.quats.begin());
  m.opacity_logits = {0.0f, 2.0f};
  std::fill(m.sh.begin(), m.sh.end(), 0.0f);
  for (uint32_t c = 0; c < channels; ++c) {
    m.sh[c] = 0.8f;                              // Gaussian 0's DC term
    m.sh[m.sh_coeffs() * channels + c] = -1.0f;  // Gaussian 1's
  }
  return m;
}

float float_at(const std::vector<uint8_t>& b, size_t row, int k) {
  float f;
  std::memcpy(&f, b.data() + row * 32 + 4 * k, 4);
  return f;
}

TEST(SplatExport, LayoutOrderAndValues) {
  const std::vector<uint8_t> b = encode_splat(two_gaussians(1));
  ASSERT_EQ(b.size(), 64u);
  // Row 0 is Gaussian 1 (exp(-3.5) * sigmoid(2) > exp(-9) * 0.5).
  EXPECT_EQ(float_at(b, 0, 0), -4.0f);
  EXPECT_EQ(float_at(b, 0, 1), 5.5f);
  EXPECT_FLOAT_EQ(float_at(b, 0, 3), std::exp(-1.0f));
  EXPECT_FLOAT_EQ(float_at(b, 0, 5), std::exp(-0.5f));
  const int gray1 = static_cast<int>(std::lround((0.5 - 0.28209479177387814) * 255));  // 0.5 + C0 * (-1)
  EXPECT_EQ(b[24], gray1);
  EXPECT_EQ(b[25], gray1);
  EXPECT_EQ(b[27], std::lround(255 / (1 + std::exp(-2.0))));
  // rotation (0.5, 0.5, -0.5, 0.5) * 128 + 128
  EXPECT_EQ(b[28], 192);
  EXPECT_EQ(b[30], 64);
  // Row 1 is Gaussian 0: quaternion (2, 0, 0, 0) normalized -> (1, 0, 0, 0) -> 255 clamped, 128, 128, 128.
  EXPECT_EQ(float_at(b, 1, 2), 3.0f);
  EXPECT_EQ(b[32 + 24], std::lround((0.5 + 0.28209479177387814 * 0.8) * 255));
  EXPECT_EQ(b[32 + 27], 128);  // sigmoid(0) = 0.5 -> 127.5 rounds to 128
  EXPECT_EQ(b[32 + 28], 255);
  EXPECT_EQ(b[32 + 29], 128);
}

TEST(SplatExport, PaletteColoursOneChannelValues) {
  SplatColouring colouring{Palette::kIronbow, 0.0, 1.0};
  const std::vector<uint8_t> b = encode_splat(two_gaussians(1), colouring);
  const double v0 = 0.5 + 0.28209479177387814 * 0.8;
  const Rgb expected = palette_table(Palette::kIronbow)[palette_index(v0, 0.0, 1.0)];
  EXPECT_EQ(b[32 + 24], expected[0]);
  EXPECT_EQ(b[32 + 25], expected[1]);
  EXPECT_EQ(b[32 + 26], expected[2]);
  EXPECT_NE(expected[0], expected[2]) << "ironbow is not gray there";
}

TEST(SplatExport, RgbModelsKeepTheirColourAndRefuseAPalette) {
  const std::vector<uint8_t> b = encode_splat(two_gaussians(3));
  EXPECT_EQ(b[32 + 24], b[32 + 26]);
  EXPECT_THROW(encode_splat(two_gaussians(3), {Palette::kGray, 0, 1}), std::invalid_argument);
  EXPECT_THROW(encode_splat(two_gaussians(1), {Palette::kGray, 1, 1}), std::invalid_argument);
}

TEST(SplatExport, CommandLineWritesTheFile) {
  const fs::path dir = fs::temp_directory_path() / ("litgs-splat-" + std::to_string(::getpid()));
  fs::create_directories(dir);
  write_gaussian_ply(dir / "m.ply", two_gaussians(1));
  const auto r = testing::run_engine("export splat --model " + (dir / "m.ply").string() + " --out " +
                                     (dir / "m.splat").string() + " --palette ironbow --range 0 1");
  ASSERT_EQ(r.status, 0) << r.output;
  std::ifstream in(dir / "m.splat", std::ios::binary);
  const std::vector<uint8_t> bytes((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
  EXPECT_EQ(bytes, encode_splat(two_gaussians(1), {Palette::kIronbow, 0, 1}));
  const auto bad = testing::run_engine("export splat --model " + (dir / "m.ply").string() + " --out " +
                                       (dir / "x.splat").string() + " --palette jet");
  EXPECT_NE(bad.status, 0);
  EXPECT_NE(bad.output.find("unknown palette 'jet'"), std::string::npos) << bad.output;
  EXPECT_FALSE(fs::exists(dir / "x.splat"));
  fs::remove_all(dir);
}

}  // namespace
}  // namespace litgs::io
