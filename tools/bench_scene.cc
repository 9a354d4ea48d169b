#include "tools/bench_scene.h"

#include <algorithm>
#include <cmath>
#include <numbers>
#include <random>

namespace litgs::tools {

kernels::SplatCamera bench_camera(uint32_t width, uint32_t height, uint32_t sh_degree) {
  kernels::SplatCamera c;
  c.width = width;
  c.height = height;
  c.fx = c.fy = 0.5 * width / std::tan(std::numbers::pi / 6.0);
  c.cx = 0.5 * width;
  c.cy = 0.5 * height;
  c.sh_degree = sh_degree;
  return c;
}

kernels::GaussianModel bench_scene(uint32_t n, uint32_t channels, uint32_t sh_degree, uint32_t width,
                                   uint32_t height, uint32_t seed) {
  const kernels::SplatCamera cam = bench_camera(width, height, sh_degree);
  kernels::GaussianModel m;
  m.channels = channels;
  m.sh_degree = sh_degree;
  m.resize(n);
  std::mt19937 rng(seed);
  std::uniform_real_distribution<double> unit(0.0, 1.0), sym(-1.0, 1.0);
  const double radius_px =
      std::clamp(std::sqrt(8.0 * width * height / (std::numbers::pi * std::max<uint32_t>(n, 1))), 0.5, 64.0);
  const uint32_t K = m.sh_coeffs();
  for (uint32_t i = 0; i < n; ++i) {
    const double z = 2.0 + 8.0 * unit(rng);
    const double u = width * unit(rng), v = height * unit(rng);
    m.means[3 * i] = static_cast<float>((u - cam.cx) / cam.fx * z);
    m.means[3 * i + 1] = static_cast<float>((v - cam.cy) / cam.fy * z);
    m.means[3 * i + 2] = static_cast<float>(z);
    // The footprint radius is about 3.3 sigma at full opacity: sigma_world = radius / 3.3 * z / f.
    const double base = std::log(radius_px / 3.3 * z / cam.fx);
    for (int a = 0; a < 3; ++a) m.log_scales[3 * i + a] = static_cast<float>(base + std::log(2.0) * sym(rng));
    for (int a = 0; a < 4; ++a) m.quats[4 * i + a] = static_cast<float>(sym(rng));
    m.opacity_logits[i] = static_cast<float>(-1.0 + 4.0 * unit(rng));
    for (uint32_t k = 0; k < K; ++k)
      for (uint32_t c = 0; c < channels; ++c)
        m.sh[(i * K + k) * channels + c] = static_cast<float>(k == 0 ? sym(rng) : 0.1 * sym(rng));
  }
  return m;
}

}  // namespace litgs::tools
