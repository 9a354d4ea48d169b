// JPEG reading on the real 8-bit DUNR frames, and corrupt files.
#include <gtest/gtest.h>

#include <fstream>

#include "io/error.h"
#include "io/image.h"
#include "io_test.h"

namespace litgs::io {
namespace {

class JpegTest : public testing::TempDirTest {};

TEST_F(JpegTest, RealRadiometricJpeg) {
  const auto path = testing::data_dir() / "thermitage-dunr" / "radjpg" / "22-18-41-880-radiometric.jpg";
  const ImageInfo info = read_image_info(path);
  EXPECT_EQ(info.width, 640);
  EXPECT_EQ(info.height, 512);
  EXPECT_EQ(info.bit_depth, 8);
  const Image img = read_image(path);
  ASSERT_NO_THROW(img.check());
  const Image gray = single_channel(img, path);
  uint16_t lo = 255, hi = 0;
  for (uint16_t v : gray.data) lo = std::min(lo, v), hi = std::max(hi, v);
  EXPECT_LT(lo, 60) << "the camera's 8-bit mapping spans most of the range";
  EXPECT_GT(hi, 200);
}

TEST_F(JpegTest, TruncatedJpegIsAnError) {
  const auto src = testing::data_dir() / "thermitage-dunr" / "radjpg" / "22-18-41-880-radiometric.jpg";
  const auto dst = dir_ / "cut.jpg";
  std::filesystem::copy_file(src, dst);
  std::filesystem::resize_file(dst, 600);
  try {
    read_image(dst);
    FAIL() << "a truncated JPEG must not decode";
  } catch (const IoError& e) {
    EXPECT_NE(std::string(e.what()).find("cut.jpg"), std::string::npos) << e.what();
  }
}

TEST_F(JpegTest, NotAJpegIsAnError) {
  EXPECT_THROW(read_image(write_text("fake.jpg", "this is not a jpeg")), IoError);
}

TEST_F(JpegTest, WritingJpegIsRefused) {
  Image img;
  img.width = img.height = 2;
  img.data.assign(4, 7);
  EXPECT_THROW(write_image(dir_ / "x.jpg", img), IoError);
}

}  // namespace
}  // namespace litgs::io
