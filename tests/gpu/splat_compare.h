// Upstream gradients and gradient comparisons shared by the rasterizer's backward tests.
#pragma once

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <random>
#include <string>
#include <vector>

#include "kernels/splat/splat_types.h"

namespace litgs::testing {

// Random upstream gradients of the image, the expected depth and the alpha map.
inline kernels::RenderGradInput random_grad(uint32_t channels, uint32_t w, uint32_t h, uint32_t seed) {
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
inline void expect_close(const std::vector<float>& got, const std::vector<double>& want,
                         const std::string& name) {
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

inline void expect_grads_match(const kernels::GaussianGrads<float>& got,
                               const kernels::GaussianGrads<double>& want) {
  expect_close(got.means, want.means, "means");
  expect_close(got.log_scales, want.log_scales, "log_scales");
  expect_close(got.quats, want.quats, "quats");
  expect_close(got.opacity_logits, want.opacity_logits, "opacity_logits");
  expect_close(got.sh, want.sh, "sh");
  expect_close(got.means2d, want.means2d, "means2d");
}

}  // namespace litgs::testing
