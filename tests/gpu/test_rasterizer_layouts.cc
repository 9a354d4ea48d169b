// The rasterize kernels' two invocation layouts (RasterizerOptions::pixels_per_invocation): 2x4 pixels per
// invocation (CPU devices' default) and one pixel (GPUs' default), both run here on one device against the
// double-precision reference, in every accumulation mode and over several list passes.
#include <gtest/gtest.h>

#include <cstring>
#include <stdexcept>

#include "gpu_test.h"
#include "kernels/splat/rasterizer.h"
#include "kernels/splat/reference.h"
#include "splat_compare.h"
#include "splat_scenes.h"

namespace litgs {
namespace {

using kernels::DeviceGaussians;
using kernels::Rasterizer;
using kernels::RasterizerOptions;

class RasterizerLayouts : public testing::GpuTest {};

TEST_F(RasterizerLayouts, TheDefaultFollowsTheDeviceTypeAndOtherSizesAreRefused) {
  Rasterizer r(context(), 1);
  EXPECT_EQ(r.pixels_per_invocation(), context().info().type == "cpu" ? 8u : 1u);
  RasterizerOptions four;
  four.pixels_per_invocation = 4;
  EXPECT_THROW(Rasterizer(context(), 1, four), std::invalid_argument);
}

TEST_F(RasterizerLayouts, BothLayoutsMatchTheReferenceInEveryMode) {
  for (uint32_t channels : {1u, 3u}) {
    const auto model = testing::random_scene(400, channels, 3, 81 + channels);
    const auto camera = testing::camera_looking_down_z(71, 45);  // partial tiles on both edges
    const auto grad = testing::random_grad(channels, camera.width, camera.height, 9);
    const auto want = kernels::reference_forward(model, camera);
    const auto want_grads = kernels::reference_backward(model, camera, grad);
    DeviceGaussians g(context(), model);
    for (uint32_t pixels : {1u, 8u})
      for (int mode = 0; mode < 3; ++mode) {
        SCOPED_TRACE("channels " + std::to_string(channels) + ", " + std::to_string(pixels) +
                     " pixels per invocation, mode " + std::to_string(mode));
        RasterizerOptions options;
        options.pixels_per_invocation = pixels;
        options.force_cas_atomics = mode == 1;
        options.deterministic = mode == 2;
        Rasterizer r(context(), channels, options);
        ASSERT_EQ(r.pixels_per_invocation(), pixels);
        r.forward(g, camera);
        const auto got = r.download_images();
        EXPECT_EQ(got.intersections, want.intersections);
        EXPECT_GE(testing::compare(got.image, want.image, 1e-4).fraction_within, 0.995);
        EXPECT_GE(testing::compare(got.depth, want.depth, 1e-4).fraction_within, 0.995);
        EXPECT_GE(testing::compare(got.alpha, want.alpha, 1e-4).fraction_within, 0.995);
        r.backward(grad);
        testing::expect_grads_match(r.download_grads(), want_grads);
      }
  }
}

// Long lists cut into many short passes (37 entries, not a multiple of any subgroup size) hand the blend and
// backward state over exactly with one pixel per invocation too: the bits of one pass.
TEST_F(RasterizerLayouts, OnePixelPerInvocationOverManyPassesEqualsOnePassBitForBit) {
  const auto model = testing::random_scene(3000, 1, 3, 91);
  const auto camera = testing::camera_looking_down_z(61, 47);
  const auto grad = testing::random_grad(1, camera.width, camera.height, 10);
  DeviceGaussians g(context(), model);
  RasterizerOptions one, many;
  one.deterministic = many.deterministic = true;
  one.pixels_per_invocation = many.pixels_per_invocation = 1;
  one.entries_per_pass = 1u << 30;
  many.entries_per_pass = 37;
  Rasterizer r1(context(), 1, one), r2(context(), 1, many);
  r1.forward(g, camera);
  r2.forward(g, camera);
  ASSERT_GT(r2.read_counters().forward_passes, 5u);
  const auto a = r1.download_images(), b = r2.download_images();
  EXPECT_EQ(0, std::memcmp(a.image.data(), b.image.data(), a.image.size() * sizeof(float)));
  EXPECT_EQ(0, std::memcmp(a.depth.data(), b.depth.data(), a.depth.size() * sizeof(float)));
  EXPECT_EQ(a.last, b.last);
  r1.backward(grad);
  r2.backward(grad);
  const auto ga = r1.download_grads(), gb = r2.download_grads();
  EXPECT_EQ(ga.means, gb.means);
  EXPECT_EQ(ga.opacity_logits, gb.opacity_logits);
  EXPECT_EQ(ga.sh, gb.sh);
  EXPECT_EQ(ga.means2d, gb.means2d);
}

}  // namespace
}  // namespace litgs
