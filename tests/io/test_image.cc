#include <gtest/gtest.h>

#include <algorithm>
#include <cstdio>

#include "io/file_bytes.h"
#include "io/image.h"
#include "tests/io/io_test.h"

namespace litgs::io {
namespace {

class ImageTest : public testing::TempDirTest {};

Image ramp(int w, int h, int channels, int depth) {
  Image im;
  im.width = w;
  im.height = h;
  im.channels = channels;
  im.bit_depth = depth;
  const int max = depth == 8 ? 255 : 65535;
  for (int i = 0; i < w * h * channels; ++i) im.data.push_back(static_cast<uint16_t>((i * 7919) % (max + 1)));
  return im;
}

std::string name_of(int channels, int depth, const char* ext) {
  char buf[64];
  std::snprintf(buf, sizeof(buf), "r%d_%d%s", channels, depth, ext);
  return buf;
}

void expect_same(const Image& a, const Image& b) {
  EXPECT_EQ(a.width, b.width);
  EXPECT_EQ(a.height, b.height);
  EXPECT_EQ(a.channels, b.channels);
  EXPECT_EQ(a.bit_depth, b.bit_depth);
  EXPECT_EQ(a.data, b.data);
}

// The real radiometric frames in tests/data: 3 of the 45 (first, middle, last), 640x512, 16-bit, no
// PhotometricInterpretation tag. Over these 3 frames the 0.5 and 99.5 percentiles are 3826 and 4165, the
// range 3109..4358, as an independent reader (Python's struct on the raw strips, no libtiff) computes them;
// see tests/data/thermitage-dunr/PROVENANCE.md. (Over all 45 frames: 3835 and 4237.)
TEST_F(ImageTest, ReadsRealRadiometricTiffs) {
  std::vector<std::filesystem::path> files;
  for (const auto& e : std::filesystem::directory_iterator(testing::data_dir() / "thermitage-dunr/radtiff"))
    files.push_back(e.path());
  ASSERT_EQ(files.size(), 3u);
  std::vector<uint64_t> histogram(65536, 0);
  uint16_t lo = 65535, hi = 0;
  for (const auto& f : files) {
    const ImageInfo info = read_image_info(f);
    EXPECT_EQ(info.width, 640);
    EXPECT_EQ(info.height, 512);
    EXPECT_EQ(info.bit_depth, 16);
    const Image im = read_image(f);
    ASSERT_EQ(im.channels, 1);
    for (uint16_t v : im.data) ++histogram[v], lo = std::min(lo, v), hi = std::max(hi, v);
  }
  const uint64_t total = 3ull * 640 * 512;
  const auto percentile = [&](double p) {
    uint64_t acc = 0;
    for (int v = 0; v < 65536; ++v)
      if ((acc += histogram[v]) >= static_cast<uint64_t>(p * static_cast<double>(total))) return v;
    return 65535;
  };
  EXPECT_NEAR(percentile(0.005), 3826, 1);
  EXPECT_NEAR(percentile(0.995), 4165, 1);
  EXPECT_EQ(lo, 3109);
  EXPECT_EQ(hi, 4358);
}

TEST_F(ImageTest, PngRoundTrips8And16Bit) {
  for (const auto& [c, d] : std::vector<std::pair<int, int>>{{1, 8}, {1, 16}, {3, 8}, {4, 16}, {2, 8}}) {
    const Image im = ramp(37, 23, c, d);
    const auto path = dir_ / name_of(c, d, ".png");
    write_image(path, im);
    expect_same(read_image(path), im);
    const ImageInfo info = read_image_info(path);
    EXPECT_EQ(info.width, 37);
    EXPECT_EQ(info.bit_depth, d);
  }
}

TEST_F(ImageTest, TiffRoundTrips8And16Bit) {
  for (const auto& [c, d] : std::vector<std::pair<int, int>>{{1, 8}, {1, 16}, {3, 16}}) {
    const Image im = ramp(41, 19, c, d);
    const auto path = dir_ / name_of(c, d, ".tiff");
    write_image(path, im);
    expect_same(read_image(path), im);
  }
}

TEST_F(ImageTest, RealTiffToPngKeepsRawCounts) {
  const Image tiff =
      read_image(testing::data_dir() / "thermitage-dunr/radtiff/22-18-41-880-radiometric.tiff");
  write_image(dir_ / "f.png", tiff);
  expect_same(read_image(dir_ / "f.png"), tiff);
}

TEST_F(ImageTest, TruncatedPngIsAnError) {
  write_image(dir_ / "full.png", ramp(64, 64, 1, 16));
  const std::string bytes = read_file_bytes(dir_ / "full.png");
  const auto path = write_text("cut.png", bytes.substr(0, bytes.size() / 2));
  EXPECT_NO_THROW(read_image_info(path));  // the header is intact
  testing::expect_io_error([&] { read_image(path); }, {"cut.png", "corrupt or truncated PNG"});
  testing::expect_io_error([&] { read_image(write_text("x.png", "not a png at all")); },
                           {"x.png", "not a PNG"});
}

TEST_F(ImageTest, TruncatedTiffIsAnError) {
  const std::string bytes =
      read_file_bytes(testing::data_dir() / "thermitage-dunr/radtiff/22-18-41-880-radiometric.tiff");
  testing::expect_io_error([&] { read_image(write_text("cut.tiff", bytes.substr(0, bytes.size() / 2))); },
                           {"cut.tiff", "TIFF"});
  testing::expect_io_error([&] { read_image(write_text("junk.tif", "II*\0junk")); }, {"junk.tif", "TIFF"});
}

TEST_F(ImageTest, BadImagesAndNamesAreRejected) {
  testing::expect_io_error([&] { read_image(dir_ / "missing.png"); }, {"missing.png", "does not exist"});
  testing::expect_io_error([&] { read_image(dir_ / "a.bmp"); }, {"a.bmp", "unknown image extension"});
  Image bad = ramp(4, 4, 1, 8);
  bad.data[3] = 300;
  EXPECT_THROW(write_image(dir_ / "bad.png", bad), std::invalid_argument);
  bad = ramp(4, 4, 1, 8);
  bad.data.pop_back();
  EXPECT_THROW(write_image(dir_ / "bad.png", bad), std::invalid_argument);
  EXPECT_FALSE(std::filesystem::exists(dir_ / "bad.png"));
}

}  // namespace
}  // namespace litgs::io
