#include "kernels/splat/splat_types.h"

#include <cmath>
#include <stdexcept>

#include "kernels/splat/splat_shared.h"

namespace litgs::kernels {

void GaussianModel::resize(size_t n) {
  means.resize(n * 3);
  log_scales.resize(n * 3);
  quats.resize(n * 4);
  opacity_logits.resize(n);
  sh.resize(n * sh_coeffs() * channels);
}

void GaussianModel::check() const {
  if (channels < 1 || channels > SPLAT_MAX_CHANNELS)
    throw std::invalid_argument("GaussianModel.channels = " + std::to_string(channels) + ", must be 1.." +
                                std::to_string(SPLAT_MAX_CHANNELS));
  if (sh_degree > 3)
    throw std::invalid_argument("GaussianModel.sh_degree = " + std::to_string(sh_degree) + ", must be 0..3");
  const size_t n = size();
  auto expect = [&](const std::vector<float>& v, size_t per, const char* name) {
    if (v.size() != n * per)
      throw std::invalid_argument(std::string("GaussianModel.") + name + " has " + std::to_string(v.size()) +
                                  " values, expected " + std::to_string(n * per) + " for " +
                                  std::to_string(n) + " Gaussians");
  };
  expect(means, 3, "means");
  expect(log_scales, 3, "log_scales");
  expect(quats, 4, "quats");
  expect(sh, static_cast<size_t>(sh_coeffs()) * channels, "sh");
}

void SplatCamera::check() const {
  auto bad = [](const char* field, double v) {
    throw std::invalid_argument(std::string("SplatCamera.") + field + " = " + std::to_string(v) +
                                " is invalid");
  };
  if (!(fx > 0) || !std::isfinite(fx)) bad("fx", fx);
  if (!(fy > 0) || !std::isfinite(fy)) bad("fy", fy);
  if (!std::isfinite(cx)) bad("cx", cx);
  if (!std::isfinite(cy)) bad("cy", cy);
  if (width == 0 || width > 16384) bad("width", width);
  if (height == 0 || height > 16384) bad("height", height);
  if (!(near_m > 0) || !std::isfinite(near_m)) bad("near_m", near_m);
  if (sh_degree > 3) bad("sh_degree", sh_degree);
  for (int c = 0; c < 3; ++c) {
    for (int r = 0; r < 3; ++r)
      if (!std::isfinite(R_cam_world[c][r])) bad("R_cam_world", R_cam_world[c][r]);
    if (!std::isfinite(t_cam_world[c])) bad("t_cam_world", t_cam_world[c]);
  }
}

}  // namespace litgs::kernels
