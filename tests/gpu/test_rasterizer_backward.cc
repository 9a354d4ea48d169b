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
#include "splat_scenes.h"

namespace litgs {
namespace {

using kernels::DeviceGaussians;
using kernels::Rasterizer;
using kernels::RasterizerOptions;

kernels::RenderGradInput random_grad(uint32_t channels, uint32_t w, uint32_t h, uint32_t seed) {
  std::mt19937 rng(seed);
  std::uniform_real_distribution<float> u(-1.0f, 1.0f);
  kernels::RenderGradInput g;
  g.image.resize(size_t{channels} * w * h);
  g.depth.resize(size_t{w} * h);
  g.alpha.resize(size_t{w} * h);
  for (auto& x : g.image) x = u(rng);
  for (auto& x : g.depth) x = 0.1f * u(rng);
  for (auto& x : g.alpha) x = u(rng);
  return g;
}

// Gradient arrays agree when their relative L2 error is small and almost every entry is close; the few
// exceptions are Gaussians whose float and double walks cross a threshold (alpha 1/255, T 1e-4) apart.
void expect_close(const std::vector<float>& got, const std::vector<double>& want, const std::string& name) {
  ASSERT_EQ(got.size(), want.size()) << name;
  double err2 = 0, ref2 = 0, scale = 0;
  for (double w : want) scale = std::max(scale, std::abs(w));
  size_t close = 0;
  for (size_t i = 0; i < got.size(); ++i) {
    ASSERT_TRUE(std::isfinite(got[i])) << name << "[" << i << "] is not finite";
    const double d = got[i] - want[i];
    err2 += d * d;
    ref2 += want[i] * want[i];
    if (std::abs(d) <= 1e-3 * scale + 1e-3 * std::abs(want[i])) ++close;
  }
  const double rel = ref2 > 0 ? std::sqrt(err2 / ref2) : std::sqrt(err2);
  EXPECT_LT(rel, 2e-3) << name << ": relative L2 error";
  EXPECT_GE(static_cast<double>(close), 0.99 * static_cast<double>(got.size())) << name << ": entries close";
}

void expect_grads_match(const kernels::GaussianGrads<float>& got, const kernels::GaussianGrads<double>& want) {
  expect_close(got.means, want.means, "means");
  expect_close(got.log_scales, want.log_scales, "log_scales");
  expect_close(got.quats, want.quats, "quats");
  expect_close(got.opacity_logits, want.opacity_logits, "opacity_logits");
  expect_close(got.sh, want.sh, "sh");
  expect_close(got.means2d, want.means2d, "means2d");
}

class RasterizerBackward : public testing::GpuTest {
 protected:
  kernels::GaussianGrads<float> device_grads(const kernels::GaussianModel& model, const kernels::SplatCamera& camera,
                                             const kernels::RenderGradInput& grad, RasterizerOptions options) {
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
    expect_grads_match(device_grads(model, camera, grad, {}), kernels::reference_backward(model, camera, grad));
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
  for (size_t i = 0; i < want.opacity_logits.size(); ++i) differs += std::abs(want.opacity_logits[i] - exact.opacity_logits[i]);
  EXPECT_GT(differs, 0.0) << "the exact gradient's opacity part depends on depth and alpha";
  for (const bool deterministic : {false, true}) {
    RasterizerOptions options;
    options.depth_gradient_to_opacity = false;
    options.deterministic = deterministic;
    SCOPED_TRACE(deterministic ? "deterministic" : "atomics");
    expect_grads_match(device_grads(model, camera, grad, options), want);
  }
}

TEST_F(RasterizerBackward, CasFallbackMatchesReference) {
  const auto model = testing::random_scene(150, 1, 3, 31);
  const auto camera = testing::camera_looking_down_z(40, 33);
  const auto grad = random_grad(1, camera.width, camera.height, 6);
  RasterizerOptions options;
  options.force_cas_atomics = true;
  expect_grads_match(device_grads(model, camera, grad, options), kernels::reference_backward(model, camera, grad));
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
