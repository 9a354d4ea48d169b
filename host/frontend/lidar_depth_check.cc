#include "host/frontend/lidar_depth_check.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <limits>
#include <stdexcept>

namespace litgs::host::frontend {

void LidarCheckOptions::check() const {
  if (!(max_transfer_px > 0)) throw std::invalid_argument("lidar_check.max_transfer_px must be > 0");
  if (cell_px < 1) throw std::invalid_argument("lidar_check.cell_px must be >= 1");
  if (window > 8) throw std::invalid_argument("lidar_check.window must be <= 8");
  if (!(edge_ratio >= 0)) throw std::invalid_argument("lidar_check.edge_ratio must be >= 0");
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
      edge_ratio_(o.edge_ratio),
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
  const auto depth_at = [&](long x, long y) {
    if (x < 0 || y < 0 || x >= static_cast<long>(cells_x_) || y >= static_cast<long>(cells_y_))
      return std::numeric_limits<float>::infinity();
    return first_depth_m_[static_cast<size_t>(y) * cells_x_ + static_cast<size_t>(x)];
  };
  const float own = depth_at(cx, cy);
  if (std::isfinite(own)) out.push_back(own);
  const long w = window_;
  for (long y = cy - w; y <= cy + w; ++y)
    for (long x = cx - w; x <= cx + w; ++x) {
      const float d = depth_at(x, y);
      if (!std::isfinite(d) || (x == cx && y == cy)) continue;
      // A neighbour on the same surface only blurs the own cell's depth (and lets a match one period off
      // pass on an oblique wall); one on another surface is a candidate at a depth edge.
      if (!std::isfinite(own) || std::abs(d - own) > edge_ratio_ * own) out.push_back(d);
    }
  return out;
}

namespace {
std::vector<Eigen::Vector2d> transfers(const DepthView& from, const DepthView& to, const PinholeK& K) {
  std::vector<Eigen::Vector2d> out;
  const std::vector<double> depths = from.depth.candidates(from.px);
  const Eigen::Vector3d ray((from.px.x() - K.cx) / K.fx, (from.px.y() - K.cy) / K.fy, 1.0);
  const Eigen::Matrix3d R_to_from = to.R_cam_world * from.R_cam_world.transpose();
  const Eigen::Vector3d t_to_from = to.t_cam_world - R_to_from * from.t_cam_world;
  for (double z : depths) {
    const Eigen::Vector3d c = R_to_from * (z * ray) + t_to_from;
    if (!(c.z() > 0)) {
      out.emplace_back(Eigen::Vector2d::Constant(std::numeric_limits<double>::infinity()));
      continue;
    }
    out.emplace_back(K.fx * c.x() / c.z() + K.cx - to.px.x(), K.fy * c.y() / c.z() + K.cy - to.px.y());
  }
  return out;
}

// The finite transfer of least norm; nullopt where none is finite.
std::optional<Eigen::Vector2d> nearest(const std::vector<Eigen::Vector2d>& transfers) {
  std::optional<Eigen::Vector2d> best;
  for (const auto& v : transfers)
    if (v.allFinite() && (!best || v.norm() < best->norm())) best = v;
  return best;
}
}  // namespace

MatchTransfers match_transfers(const DepthView& a, const DepthView& b, const PinholeK& K) {
  return {transfers(a, b, K), transfers(b, a, K)};
}

std::optional<double> lidar_transfer_px(const std::vector<Eigen::Vector2d>& transfers,
                                        const Eigen::Vector2d& offset) {
  if (transfers.empty()) return std::nullopt;
  double best = std::numeric_limits<double>::infinity();
  for (const auto& v : transfers)
    if (v.allFinite()) best = std::min(best, (v - offset).norm());
  return best;
}

PairTransferOffset pair_transfer_offset(const std::vector<MatchTransfers>& matches, size_t min_matches) {
  std::array<std::vector<double>, 4> axes;  // ab x, ab y, ba x, ba y
  for (const MatchTransfers& m : matches) {
    if (const auto t = nearest(m.ab)) {
      axes[0].push_back(t->x());
      axes[1].push_back(t->y());
    }
    if (const auto t = nearest(m.ba)) {
      axes[2].push_back(t->x());
      axes[3].push_back(t->y());
    }
  }
  const auto median = [](std::vector<double>& v) {
    std::nth_element(v.begin(), v.begin() + static_cast<long>(v.size() / 2), v.end());
    return v[v.size() / 2];
  };
  PairTransferOffset o;
  if (axes[0].size() >= std::max<size_t>(min_matches, 1)) o.ab = {median(axes[0]), median(axes[1])};
  if (axes[2].size() >= std::max<size_t>(min_matches, 1)) o.ba = {median(axes[2]), median(axes[3])};
  return o;
}

bool contradicted_by_lidar(const MatchTransfers& m, double bound_px, const Eigen::Vector2d& offset_ab,
                           const Eigen::Vector2d& offset_ba) {
  const std::optional<double> ab = lidar_transfer_px(m.ab, offset_ab),
                              ba = lidar_transfer_px(m.ba, offset_ba);
  if (!ab && !ba) return false;
  return !(ab && *ab <= bound_px) && !(ba && *ba <= bound_px);
}

}  // namespace litgs::host::frontend
