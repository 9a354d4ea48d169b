// Backward rasterization on the device against the double-precision reference (itself checked against
// finite differences in tests/kernels), in all three accumulation modes, and bit-identical determinism.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstring>
#include <random>
#include <string>

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

using testing::expect_grads_match;
using testing::random_grad;

class RasterizerBackward : public testing::GpuTest {
 protected:
  kernels::GaussianGrads<float> device_grads(const kernels::GaussianModel& model,
                                             const kernels::SplatCamera& camera,
                                             const kernels::RenderGradInput& grad,
                                             RasterizerOptions options) {
    DeviceGaussians g(context(), model);
    Rasterizer r(context(), model.channels, options);
    r.forward(g, camera);
    r.backward(grad);
    return r.download_grads();
  }
};

TEST_F(RasterizerBackward, AtomicModeMatchesReference) {
  for (uint32_t channels : {1u, 3u}) {
    const auto model = testing::random_scene(200, channels, 3, 21 + channels);
    const auto camera = testing::camera_looking_down_z(50, 38);
    const auto grad = random_grad(channels, camera.width, camera.height, 5);
    SCOPED_TRACE("channels " + std::to_string(channels));
    expect_grads_match(device_grads(model, camera, grad, {}),
                       kernels::reference_backward(model, camera, grad));
  }
}

TEST_F(RasterizerBackward, DepthGradientWithoutOpacityMatchesReference) {
  // The LiDAR term's routing: the depth and alpha gradients skip the opacity. The device must agree with the
  // reference's routing in every accumulation mode, and the opacity gradient must then equal the one of the
  // image gradient alone.
  const auto model = testing::random_scene(200, 1, 3, 51);
  const auto camera = testing::camera_looking_down_z(50, 38);
  const auto grad = random_grad(1, camera.width, camera.height, 8);
  kernels::RenderGradInput image_only = grad;
  std::fill(image_only.depth.begin(), image_only.depth.end(), 0.0f);
  std::fill(image_only.alpha.begin(), image_only.alpha.end(), 0.0f);
  const auto want = kernels::reference_backward(model, camera, grad, false);
  const auto exact = kernels::reference_backward(model, camera, grad, true);
  const auto image_want = kernels::reference_backward(model, camera, image_only, true);
  for (size_t i = 0; i < want.opacity_logits.size(); ++i)
    ASSERT_DOUBLE_EQ(want.opacity_logits[i], image_want.opacity_logits[i]) << "Gaussian " << i;
  double moved = 0;
  for (size_t i = 0; i < want.means.size(); ++i) moved += std::abs(want.means[i] - image_want.means[i]);
  EXPECT_GT(moved, 0.0) << "the depth gradient still moves the means";
  double differs = 0;
  for (size_t i = 0; i < want.opacity_logits.size(); ++i)
    differs += std::abs(want.opacity_logits[i] - exact.opacity_logits[i]);
  EXPECT_GT(differs, 0.0) << "the exact gradient's opacity part depends on depth and alpha";
  for (const bool deterministic : {false, true}) {
    RasterizerOptions options;
    options.depth_gradient_to_opacity = false;
    options.deterministic = deterministic;
    SCOPED_TRACE(deterministic ? "deterministic" : "atomics");
    expect_grads_match(device_grads(model, camera, grad, options), want);
  }
}

TEST_F(RasterizerBackward, ThinDiagonalFootprintsMatchReference) {
  // Needles at 20-70 degrees in the image plane: their footprints' bounding boxes are mostly empty, which is
  // where a subgroup's exact ellipse-box test (kernels/splat/footprint.glsl) skips the most entries. Skipping
  // must drop no contribution: images and gradients as the reference, the same intersections.
  auto model = testing::random_scene(200, 1, 3, 61);
  std::mt19937 rng(62);
  std::uniform_real_distribution<float> angle(0.35f, 1.22f), long_axis(-1.5f, -0.5f);
  for (size_t i = 0; i < model.size(); ++i) {
    const float half = 0.5f * angle(rng);  // a rotation about the camera's z axis
    model.quats[4 * i] = std::cos(half);
    model.quats[4 * i + 1] = 0.0f;
    model.quats[4 * i + 2] = 0.0f;
    model.quats[4 * i + 3] = (i % 2 ? 1.0f : -1.0f) * std::sin(half);
    model.log_scales[3 * i] = long_axis(rng);
    model.log_scales[3 * i + 1] = -5.0f;
    model.log_scales[3 * i + 2] = -5.0f;
  }
  const auto camera = testing::camera_looking_down_z(64, 48);
  DeviceGaussians g(context(), model);
  Rasterizer r(context(), 1);
  r.forward(g, camera);
  const auto got = r.download_images();
  const auto want = kernels::reference_forward(model, camera);
  EXPECT_EQ(got.intersections, want.intersections);
  EXPECT_GE(testing::compare(got.image, want.image, 1e-4).fraction_within, 0.999);
  EXPECT_GE(testing::compare(got.alpha, want.alpha, 1e-4).fraction_within, 0.999);
  EXPECT_GT(r.read_counters().contributions, 0u);
  const auto grad = random_grad(1, camera.width, camera.height, 63);
  expect_grads_match(device_grads(model, camera, grad, {}), kernels::reference_backward(model, camera, grad));
}

TEST_F(RasterizerBackward, CasFallbackMatchesReference) {
  const auto model = testing::random_scene(150, 1, 3, 31);
  const auto camera = testing::camera_looking_down_z(40, 33);
  const auto grad = random_grad(1, camera.width, camera.height, 6);
  RasterizerOptions options;
  options.force_cas_atomics = true;
  expect_grads_match(device_grads(model, camera, grad, options),
                     kernels::reference_backward(model, camera, grad));
}

TEST_F(RasterizerBackward, DeterministicModeMatchesReferenceAndIsBitIdentical) {
  const auto model = testing::random_scene(250, 1, 3, 41);
  const auto camera = testing::camera_looking_down_z(48, 40);
  const auto grad = random_grad(1, camera.width, camera.height, 7);
  RasterizerOptions options;
  options.deterministic = true;
  const auto a = device_grads(model, camera, grad, options);
  const auto b = device_grads(model, camera, grad, options);
  expect_grads_match(a, kernels::reference_backward(model, camera, grad));
  auto same_bits = [](const std::vector<float>& x, const std::vector<float>& y) {
    return x.size() == y.size() && std::memcmp(x.data(), y.data(), x.size() * sizeof(float)) == 0;
  };
  EXPECT_TRUE(same_bits(a.means, b.means));
  EXPECT_TRUE(same_bits(a.log_scales, b.log_scales));
  EXPECT_TRUE(same_bits(a.quats, b.quats));
  EXPECT_TRUE(same_bits(a.opacity_logits, b.opacity_logits));
  EXPECT_TRUE(same_bits(a.sh, b.sh));
  EXPECT_TRUE(same_bits(a.means2d, b.means2d));
}

}  // namespace
}  // namespace litgs
