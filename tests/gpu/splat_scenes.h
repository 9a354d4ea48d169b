// Scenes and comparisons shared by the rasterizer's GPU tests.
#pragma once

#include <algorithm>
#include <cmath>
#include <random>
#include <vector>

#include "kernels/splat/splat_types.h"

namespace litgs::testing {

// N random Gaussians in front of a camera at the origin looking down +z, spread over its view.
inline kernels::GaussianModel random_scene(size_t n, uint32_t channels, uint32_t degree, uint32_t seed,
                                           double fov_half_tan = 0.5) {
  kernels::GaussianModel m;
  m.channels = channels;
  m.sh_degree = degree;
  m.resize(n);
  std::mt19937 rng(seed);
  std::uniform_real_distribution<float> u(-1.0f, 1.0f), depth(1.5f, 6.0f), ls(-3.5f, -1.5f), op(-2.0f, 3.0f);
  for (size_t i = 0; i < n; ++i) {
    const float z = depth(rng);
    m.means[3 * i] = u(rng) * z * static_cast<float>(fov_half_tan);
    m.means[3 * i + 1] = u(rng) * z * static_cast<float>(fov_half_tan);
    m.means[3 * i + 2] = z;
    for (int a = 0; a < 3; ++a) m.log_scales[3 * i + a] = ls(rng);
    for (int a = 0; a < 4; ++a) m.quats[4 * i + a] = u(rng);
    m.opacity_logits[i] = op(rng);
  }
  for (auto& c : m.sh) c = 0.2f * u(rng);
  for (size_t i = 0; i < n; ++i)
    for (uint32_t c = 0; c < channels; ++c) m.sh[i * m.sh_coeffs() * channels + c] = 0.5f + 0.5f * u(rng);
  return m;
}

inline kernels::SplatCamera camera_looking_down_z(uint32_t width, uint32_t height,
                                                  double fov_half_tan = 0.5) {
  kernels::SplatCamera c;
  c.width = width;
  c.height = height;
  c.fx = c.fy = 0.5 * width / fov_half_tan;
  c.cx = 0.5 * width;
  c.cy = 0.5 * height;
  return c;
}

struct Agreement {
  double max_abs = 0.0;
  double fraction_within = 0.0;  // of values within the tight tolerance
  size_t count = 0;
};

template <class A, class B>
Agreement compare(const std::vector<A>& got, const std::vector<B>& want, double tight) {
  Agreement r;
  r.count = std::min(got.size(), want.size());
  size_t within = 0;
  for (size_t i = 0; i < r.count; ++i) {
    const double d = std::abs(static_cast<double>(got[i]) - static_cast<double>(want[i]));
    r.max_abs = std::max(r.max_abs, std::isfinite(d) ? d : 1e300);
    if (d <= tight) ++within;
  }
  r.fraction_within = r.count ? static_cast<double>(within) / static_cast<double>(r.count) : 1.0;
  return r;
}

}  // namespace litgs::testing
