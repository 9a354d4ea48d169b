// Forward rasterization on the device against the double-precision reference.
#include <gtest/gtest.h>

#include <algorithm>

#include "gpu_test.h"
#include "kernels/splat/rasterizer.h"
#include "kernels/splat/reference.h"
#include "splat_scenes.h"

namespace litgs {
namespace {

using kernels::DeviceGaussians;
using kernels::Rasterizer;

class RasterizerForward : public testing::GpuTest {};

TEST_F(RasterizerForward, RandomSceneMatchesReference) {
  for (uint32_t channels : {1u, 3u}) {
    const auto model = testing::random_scene(300, channels, 3, 11 + channels);
    const auto camera = testing::camera_looking_down_z(67, 45);
    DeviceGaussians g(context(), model);
    Rasterizer r(context(), channels);
    r.forward(g, camera);
    const auto got = r.download_images();
    const auto want = kernels::reference_forward(model, camera);
    EXPECT_EQ(got.intersections, want.intersections);
    const auto img = testing::compare(got.image, want.image, 1e-4);
    const auto dep = testing::compare(got.depth, want.depth, 1e-4);
    const auto alp = testing::compare(got.alpha, want.alpha, 1e-4);
    std::printf("C=%u image max %.3g within %.4f | depth max %.3g within %.4f | alpha max %.3g within %.4f\n",
                channels, img.max_abs, img.fraction_within, dep.max_abs, dep.fraction_within, alp.max_abs,
                alp.fraction_within);
    EXPECT_GE(img.fraction_within, 0.995);
    EXPECT_GE(dep.fraction_within, 0.995);
    EXPECT_GE(alp.fraction_within, 0.995);
  }
}

TEST_F(RasterizerForward, CountsOneBlendedPairPerCoveredPixelOfOneGaussian) {
  // bench render's useful FLOP/s rest on the forward's count of blended (pixel, Gaussian) pairs: with one
  // Gaussian that is the number of pixels it reaches (alpha > 0), here a few hundred of 64x48.
  auto model = testing::random_scene(1, 1, 3, 71);
  model.means = {0.05f, -0.03f, 3.0f};
  model.log_scales = {-1.8f, -2.2f, -2.0f};
  const auto camera = testing::camera_looking_down_z(64, 48);
  DeviceGaussians g(context(), model);
  Rasterizer r(context(), 1);
  r.forward(g, camera);
  const auto images = r.download_images();
  const auto covered = static_cast<uint32_t>(
      std::count_if(images.alpha.begin(), images.alpha.end(), [](float a) { return a > 0; }));
  EXPECT_GT(covered, 100u);
  EXPECT_LT(covered, 64u * 48u);
  EXPECT_EQ(r.read_counters().contributions, covered);
}

}  // namespace
}  // namespace litgs
