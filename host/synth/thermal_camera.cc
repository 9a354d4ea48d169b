#include "host/synth/thermal_camera.h"

#include <algorithm>
#include <cmath>
#include <numbers>
#include <thread>
#include <vector>

#include "host/synth/rng.h"
#include "io/lens_distortion.h"

namespace litgs::host::synth {

std::string ThermalCameraOptions::check() const {
  if (width < 16 || width > 8192) return "width: must be in [16, 8192]";
  if (height < 16 || height > 8192) return "height: must be in [16, 8192]";
  if (!(hfov_deg > 1 && hfov_deg < 170)) return "hfov_deg: must be in (1, 170)";
  if (calibrated) {
    const io::CameraIntrinsics& k = *calibrated;
    if (k.width != width || k.height != height) return "calibrated: its size differs from width x height";
    if (!(k.fx > 0 && k.fy > 0 && std::isfinite(k.cx) && std::isfinite(k.cy)))
      return "calibrated: fx and fy must be positive, cx and cy finite";
  }
  if (!(temporal_noise_raw >= 0)) return "temporal_noise_raw: must be >= 0";
  if (!(fixed_pattern_raw >= 0)) return "fixed_pattern_raw: must be >= 0";
  if (!(vignetting_raw >= 0)) return "vignetting_raw: must be >= 0";
  if (!(column_noise_raw >= 0)) return "column_noise_raw: must be >= 0";
  if (!(blur_px >= 0 && blur_px <= 5)) return "blur_px: must be in [0, 5]";
  if (!(agc_low_percentile >= 0 && agc_low_percentile < agc_high_percentile && agc_high_percentile <= 100))
    return "agc_low_percentile/agc_high_percentile: need 0 <= low < high <= 100";
  return "";
}

io::CameraIntrinsics ThermalCameraOptions::intrinsics() const {
  if (calibrated) {
    io::CameraIntrinsics K = *calibrated;
    K.bit_depth = 16;
    return K;
  }
  io::CameraIntrinsics K;
  K.width = width;
  K.height = height;
  K.fx = K.fy = width / (2 * std::tan(hfov_deg * std::numbers::pi / 360));
  K.cx = (width - 1) / 2.0;
  K.cy = (height - 1) / 2.0;
  K.bit_depth = 16;
  return K;
}

double pixel_radiance(const World& world, const io::CameraIntrinsics& K, const Eigen::Isometry3d& T_world_cam,
                      double x, double y) {
  const std::optional<Eigen::Vector3d> ray = io::pixel_ray(K, x, y);
  if (!ray) return world.sky_raw;
  const Eigen::Vector3d d_cam = *ray;
  const Eigen::Vector3d dir = T_world_cam.linear() * d_cam.normalized();
  const auto hit = world.cast({T_world_cam.translation(), dir}, 0.05, 1e4);
  if (!hit) return world.sky_raw;
  // The pixel's footprint on the surface, stretched at grazing incidence: what the joints are filtered over.
  const double cos_incidence = std::max(0.1, std::abs(hit->normal.dot(dir)));
  const double footprint = hit->range_m / (K.fx * d_cam.normalized().z()) / cos_incidence;
  return thermal_radiance(world.textures[hit->texture], hit->u_m, hit->v_m, footprint);
}

io::Image true_depth_mm(const World& world, const io::CameraIntrinsics& K,
                        const Eigen::Isometry3d& T_world_cam) {
  io::Image depth;
  depth.width = K.width;
  depth.height = K.height;
  depth.bit_depth = 16;
  depth.data.assign(static_cast<size_t>(K.width) * K.height, 0);
  for (int y = 0; y < K.height; ++y)
    for (int x = 0; x < K.width; ++x) {
      const std::optional<Eigen::Vector3d> ray = io::pixel_ray(K, x, y);
      if (!ray) continue;
      const Eigen::Vector3d d_cam = *ray;
      const auto hit =
          world.cast({T_world_cam.translation(), T_world_cam.linear() * d_cam.normalized()}, 0.05, 1e4);
      if (!hit) continue;
      const double z_mm = 1000.0 * hit->range_m * d_cam.normalized().z();
      if (z_mm < 65535.5)
        depth.data[static_cast<size_t>(y) * K.width + x] = static_cast<uint16_t>(std::lround(z_mm));
    }
  return depth;
}

namespace {

// Separable Gaussian blur of a row-major image in place (edges clamped): the optics' point spread.
void gaussian_blur(std::vector<double>& image, int width, int height, double sigma_px) {
  if (sigma_px <= 0) return;
  const int radius = static_cast<int>(std::ceil(3 * sigma_px));
  std::vector<double> kernel(2 * radius + 1);
  double sum = 0;
  for (int k = -radius; k <= radius; ++k)
    sum += kernel[k + radius] = std::exp(-k * k / (2 * sigma_px * sigma_px));
  for (double& k : kernel) k /= sum;
  std::vector<double> tmp(image.size());
  auto pass = [&](const std::vector<double>& in, std::vector<double>& out, bool along_x) {
    for (int y = 0; y < height; ++y)
      for (int x = 0; x < width; ++x) {
        double acc = 0;
        for (int k = -radius; k <= radius; ++k) {
          const int xx = along_x ? std::clamp(x + k, 0, width - 1) : x;
          const int yy = along_x ? y : std::clamp(y + k, 0, height - 1);
          acc += kernel[k + radius] * in[static_cast<size_t>(yy) * width + xx];
        }
        out[static_cast<size_t>(y) * width + x] = acc;
      }
  };
  pass(image, tmp, true);
  pass(tmp, image, false);
}

}  // namespace

io::Image render_thermal(const World& world, const ThermalCameraOptions& o,
                         const Eigen::Isometry3d& T_world_cam, uint64_t seed, uint64_t frame_index,
                         int threads) {
  const io::CameraIntrinsics K = o.intrinsics();
  const size_t pixels = static_cast<size_t>(K.width) * K.height;
  // The scene's radiance through the optics first, then the sensor's noise on top of it.
  std::vector<double> radiance(pixels);
  auto render_rows = [&](int y0, int step) {
    for (int y = y0; y < K.height; y += step)
      for (int x = 0; x < K.width; ++x)
        radiance[static_cast<size_t>(y) * K.width + x] = pixel_radiance(world, K, T_world_cam, x, y);
  };
  threads = std::clamp(threads, 1, 64);
  std::vector<std::thread> pool;
  for (int i = 1; i < threads; ++i) pool.emplace_back(render_rows, i, threads);
  render_rows(0, threads);
  for (auto& t : pool) t.join();
  gaussian_blur(radiance, K.width, K.height, o.blur_px);

  const uint64_t frame_key =
      hash_combine(hash_combine(seed, static_cast<uint64_t>(Stream::kThermal)), frame_index);
  const uint64_t pattern_key =
      hash_combine(hash_combine(seed, static_cast<uint64_t>(Stream::kThermal)), ~0ull);
  const uint64_t column_key = hash_combine(pattern_key, 0xc01ull);
  const double r2_corner = K.cx * K.cx + K.cy * K.cy;
  io::Image image;
  image.width = K.width;
  image.height = K.height;
  image.bit_depth = 16;
  image.data.assign(pixels, 0);
  for (int y = 0; y < K.height; ++y)
    for (int x = 0; x < K.width; ++x) {
      const uint64_t pixel = static_cast<uint64_t>(y) * K.width + x;
      double raw = radiance[pixel];
      const double r2 = ((x - K.cx) * (x - K.cx) + (y - K.cy) * (y - K.cy)) / r2_corner;
      raw -= o.vignetting_raw * r2;
      raw += o.fixed_pattern_raw * hash_normal(hash_combine(pattern_key, pixel));
      if (o.column_noise_raw > 0)
        raw += o.column_noise_raw * hash_normal(hash_combine(column_key, static_cast<uint64_t>(x)));
      raw += o.temporal_noise_raw * hash_normal(hash_combine(frame_key, pixel));
      image.data[pixel] = static_cast<uint16_t>(std::clamp(std::lround(raw), 0l, 65535l));
    }
  return image;
}

io::Image auto_gain_8bit(const io::Image& raw, const ThermalCameraOptions& o) {
  std::vector<uint16_t> values = raw.data;
  auto percentile = [&](double p) {
    const auto i = static_cast<size_t>(std::lround(p / 100 * static_cast<double>(values.size() - 1)));
    std::nth_element(values.begin(), values.begin() + static_cast<std::ptrdiff_t>(i), values.end());
    return static_cast<double>(values[i]);
  };
  const double lo = percentile(o.agc_low_percentile);
  const double hi = std::max(percentile(o.agc_high_percentile), lo + 1);
  io::Image out = raw;
  out.bit_depth = 8;
  for (auto& v : out.data)
    v = static_cast<uint16_t>(std::clamp(std::lround((v - lo) / (hi - lo) * 255), 0l, 255l));
  return out;
}

}  // namespace litgs::host::synth
