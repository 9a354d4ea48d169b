// The report's pictures: palettes at their ends and in between, masks, and the files written for a view.
#include <gtest/gtest.h>
#include <unistd.h>

#include <filesystem>

#include "host/eval/view_images.h"
#include "io/image.h"

namespace litgs::host {
namespace {

TEST(ViewImages, PaletteEndsAndMonotoneBrightness) {
  EXPECT_EQ(palette_colour(Palette::kThermal, 0.0), (std::array<uint8_t, 3>{0, 0, 0}));
  EXPECT_EQ(palette_colour(Palette::kThermal, 1.0), (std::array<uint8_t, 3>{255, 255, 255}));
  EXPECT_EQ(palette_colour(Palette::kThermal, -3.0), palette_colour(Palette::kThermal, 0.0));  // clamped
  EXPECT_EQ(palette_colour(Palette::kError, 0.0), (std::array<uint8_t, 3>{0, 0, 0}));
  // Brighter with the value (sum of channels), so that the ramps read as ramps.
  for (Palette p : {Palette::kThermal, Palette::kError, Palette::kDepth}) {
    int previous = -1;
    for (int k = 0; k <= 20; ++k) {
      const auto c = palette_colour(p, k / 20.0);
      const int sum = c[0] + c[1] + c[2];
      EXPECT_GE(sum, previous) << "palette " << static_cast<int>(p) << " at " << k / 20.0;
      previous = sum;
    }
  }
}

TEST(ViewImages, WritesTheFivePictures) {
  const auto dir =
      std::filesystem::temp_directory_path() / ("litgs-view-images-" + std::to_string(::getpid()));
  std::filesystem::remove_all(dir);
  std::filesystem::create_directories(dir);
  ViewImages v{"1.500000.png", 4, 2, {}, {}, {}, {}};
  v.render = {0, 0.25f, 0.5f, 1, 0, 0, 0, 0};
  v.target = {0, 0.25f, 0.5f, 0.5f, 0, 0, 0, 0};
  v.depth_m = {2, 3, 4, 5, 9, 9, 9, 9};
  v.alpha = {1, 1, 1, 1, 0, 0, 0, 0};
  const nlohmann::json j = write_view_images(dir, v);
  EXPECT_EQ(j["render"], "1.500000.render.png");
  EXPECT_DOUBLE_EQ(j["depth_min_m"].get<double>(), 2.0);
  EXPECT_DOUBLE_EQ(j["depth_max_m"].get<double>(), 5.0);  // transparent pixels excluded
  const io::Image render = io::read_image(dir / "1.500000.render.png");
  EXPECT_EQ(render.at(2, 0), 128);
  const io::Image error = io::read_image(dir / "1.500000.error.png");
  ASSERT_EQ(error.channels, 3);
  EXPECT_EQ(error.at(0, 0, 0), 0);    // no error: black
  EXPECT_EQ(error.at(3, 0, 1), 255);  // 0.5 error, above full scale: white
  const io::Image depth = io::read_image(dir / "1.500000.depth.png");
  EXPECT_EQ(depth.at(0, 1, 0) + depth.at(0, 1, 1) + depth.at(0, 1, 2), 0);  // transparent: black
  EXPECT_TRUE(std::filesystem::exists(dir / "1.500000.false.png"));
  EXPECT_TRUE(std::filesystem::exists(dir / "1.500000.target.png"));
  EXPECT_FALSE(j["error_uncovered_shown"].get<bool>());  // no mask: the error map as it was

  // With a co-visibility mask, the pixels no training view saw take the blue ramp: the same error (0.5,
  // above full scale) is white either way, a mid error is orange where covered and blue where not.
  v.render = {0, 0.25f, 0.5f, 1, 0.1f, 0.1f, 0, 0};
  v.covisible = {1, 1, 1, 0, 1, 0, 1, 1};
  const nlohmann::json masked = write_view_images(dir, v);
  EXPECT_TRUE(masked["error_uncovered_shown"].get<bool>());
  const io::Image with_mask = io::read_image(dir / "1.500000.error.png");
  EXPECT_EQ(with_mask.at(3, 0, 1), 255);
  const auto covered = palette_colour(Palette::kError, 0.1 / kErrorFullScale);
  const auto uncovered = palette_colour(Palette::kErrorUncovered, 0.1 / kErrorFullScale);
  for (int c = 0; c < 3; ++c) {
    EXPECT_EQ(with_mask.at(0, 1, c), covered[c]);
    EXPECT_EQ(with_mask.at(1, 1, c), uncovered[c]);
  }
  EXPECT_GT(uncovered[2], uncovered[0]);  // blue, where the covered ramp is red
  EXPECT_GT(covered[0], covered[2]);
  std::filesystem::remove_all(dir);
}

}  // namespace
}  // namespace litgs::host
