#include "host/frontend/lidar_depth_check.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <stdexcept>

namespace litgs::host::frontend {

void LidarCheckOptions::check() const {
  if (!(max_transfer_px > 0)) throw std::invalid_argument("lidar_check.max_transfer_px must be > 0");
  if (cell_px < 1) throw std::invalid_argument("lidar_check.cell_px must be >= 1");
  if (window > 8) throw std::invalid_argument("lidar_check.window must be <= 8");
  if (!(min_depth_m > 0)) throw std::invalid_argument("lidar_check.min_depth_m must be > 0");
}

LidarDepthImage::LidarDepthImage(const std::vector<Eigen::Vector3d>& map_world,
                                 const Eigen::Matrix3d& R_cam_world, const Eigen::Vector3d& t_cam_world,
                                 const PinholeK& K, uint32_t width, uint32_t height,
                                 const LidarCheckOptions& o)
    : cells_x_((width + o.cell_px - 1) / o.cell_px),
      cells_y_((height + o.cell_px - 1) / o.cell_px),
      cell_px_(o.cell_px),
      window_(o.window),
      first_depth_m_(static_cast<size_t>(cells_x_) * cells_y_, std::numeric_limits<float>::infinity()) {
  for (const Eigen::Vector3d& x : map_world) {
    const Eigen::Vector3d c = R_cam_world * x + t_cam_world;
    if (!(c.z() > o.min_depth_m)) continue;
    // Pixel centres at integers: a cell spans [k * cell - 0.5, (k + 1) * cell - 0.5).
    const double u = K.fx * c.x() / c.z() + K.cx + 0.5, v = K.fy * c.y() / c.z() + K.cy + 0.5;
    if (!(u >= 0 && v >= 0 && u < width && v < height)) continue;
    const size_t cell = static_cast<size_t>(v / cell_px_) * cells_x_ + static_cast<size_t>(u / cell_px_);
    first_depth_m_[cell] = std::min(first_depth_m_[cell], static_cast<float>(c.z()));
  }
}

std::vector<double> LidarDepthImage::candidates(const Eigen::Vector2d& px) const {
  std::vector<double> out;
  if (!px.allFinite()) return out;
  const long cx = static_cast<long>(std::floor((px.x() + 0.5) / cell_px_));
  const long cy = static_cast<long>(std::floor((px.y() + 0.5) / cell_px_));
  const long w = window_;
  for (long y = std::max(0L, cy - w); y <= std::min<long>(cells_y_ - 1, cy + w); ++y)
    for (long x = std::max(0L, cx - w); x <= std::min<long>(cells_x_ - 1, cx + w); ++x) {
      const float d = first_depth_m_[static_cast<size_t>(y) * cells_x_ + static_cast<size_t>(x)];
      if (std::isfinite(d)) out.push_back(d);
    }
  return out;
}

std::optional<double> lidar_transfer_px(const DepthView& from, const DepthView& to, const PinholeK& K) {
  const std::vector<double> depths = from.depth.candidates(from.px);
  if (depths.empty()) return std::nullopt;
  const Eigen::Vector3d ray((from.px.x() - K.cx) / K.fx, (from.px.y() - K.cy) / K.fy, 1.0);
  const Eigen::Matrix3d R_to_from = to.R_cam_world * from.R_cam_world.transpose();
  const Eigen::Vector3d t_to_from = to.t_cam_world - R_to_from * from.t_cam_world;
  double best = std::numeric_limits<double>::infinity();
  for (double z : depths) {
    const Eigen::Vector3d c = R_to_from * (z * ray) + t_to_from;
    if (!(c.z() > 0)) continue;
    best = std::min(
        best, std::hypot(K.fx * c.x() / c.z() + K.cx - to.px.x(), K.fy * c.y() / c.z() + K.cy - to.px.y()));
  }
  return best;
}

bool contradicted_by_lidar(const DepthView& a, const DepthView& b, const PinholeK& K, double bound_px) {
  const std::optional<double> ab = lidar_transfer_px(a, b, K), ba = lidar_transfer_px(b, a, K);
  if (!ab && !ba) return false;
  return !(ab && *ab <= bound_px) && !(ba && *ba <= bound_px);
}

}  // namespace litgs::host::frontend
