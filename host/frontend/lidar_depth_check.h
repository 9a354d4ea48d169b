// Match verification by the LiDAR map. A repeated texture (bricks, windows, panels) matched one period off
// still lies on the prior's epipolar line and fits the pair's essential matrix, but it puts the point at a
// depth the map does not have. Lifting a keypoint to the map's first surface under it and projecting it
// into the other image through the prior poses exposes it; a true match lands near its partner.
//
// Approximate: the map is a point cloud, so a cell's first surface is its nearest sample; a cell without
// samples borrows its neighbours', and at a depth edge every nearby first surface is a candidate (the
// check then passes if any of them explains the match, so it errs towards keeping).
#pragma once

#include <Eigen/Core>
#include <cstdint>
#include <optional>
#include <vector>

#include "host/frontend/verification.h"

namespace litgs::host::frontend {

struct LidarCheckOptions {
  bool enabled = true;  // used where the scene has lidar/map.pcd and both images a prior pose
  // A match is kept when the map's depth carries one keypoint to within this of the other (undistorted
  // pixels), once the pair's common transfer is removed: the priors' relative error moves every match of a
  // pair alike, and what is left is the match's own error (docs/frontend.md, docs/experiments.md).
  double max_transfer_px = 3;
  uint32_t cell_px = 4;  // z-buffer cell edge (pixels)
  uint32_t window = 1;   // cells on each side whose first surfaces are also candidates...
  // ...where the keypoint's own cell has none, or theirs differs from its own by more than this share
  // (another surface: a depth edge)
  double edge_ratio = 0.2;
  double min_depth_m = 0.1;
  void check() const;  // std::invalid_argument naming the bad field
};

// The map's first surface per cell of one view (undistorted pinhole pixels of the scene camera).
class LidarDepthImage {
 public:
  LidarDepthImage(const std::vector<Eigen::Vector3d>& map_world, const Eigen::Matrix3d& R_cam_world,
                  const Eigen::Vector3d& t_cam_world, const PinholeK& K, uint32_t width, uint32_t height,
                  const LidarCheckOptions& options);
  // The first-surface depths (metres along the optical axis) in the window around pixel `px`; empty where
  // the map has no sample there.
  std::vector<double> candidates(const Eigen::Vector2d& px) const;

 private:
  uint32_t cells_x_ = 0, cells_y_ = 0, cell_px_ = 1, window_ = 0;
  double edge_ratio_ = 0;
  std::vector<float> first_depth_m_;  // [cells_y][cells_x], +inf where no sample projects
};

// One view of a match: the prior pose (camera from world), the keypoint's undistorted pixel and the view's
// depth image.
struct DepthView {
  const Eigen::Matrix3d& R_cam_world;
  const Eigen::Vector3d& t_cam_world;
  const Eigen::Vector2d& px;
  const LidarDepthImage& depth;
};

// A match's transfers: a keypoint lifted to each of its candidate depths and projected into the other view,
// less the partner's pixel (infinite where it lands behind that camera), in both directions. Computed once
// per match: the pair's offset and the bound are both judged on them.
struct MatchTransfers {
  std::vector<Eigen::Vector2d> ab, ba;  // empty where that direction's keypoint has no candidate depth
};
MatchTransfers match_transfers(const DepthView& a, const DepthView& b, const PinholeK& K);

// The smallest distance of one direction's transfers from `offset`; nullopt where there are none (the map
// cannot judge).
std::optional<double> lidar_transfer_px(const std::vector<Eigen::Vector2d>& transfers,
                                        const Eigen::Vector2d& offset = Eigen::Vector2d::Zero());

// A pair's common transfer in each direction: the per-axis median of its matches' nearest transfers
// (zero with fewer than `min_matches` that the map can judge).
struct PairTransferOffset {
  Eigen::Vector2d ab = Eigen::Vector2d::Zero(), ba = Eigen::Vector2d::Zero();
};
PairTransferOffset pair_transfer_offset(const std::vector<MatchTransfers>& matches, size_t min_matches);

// Whether the map contradicts the match: some direction could be judged and none transfers within bound
// of its offset.
bool contradicted_by_lidar(const MatchTransfers& m, double bound_px,
                           const Eigen::Vector2d& offset_ab = Eigen::Vector2d::Zero(),
                           const Eigen::Vector2d& offset_ba = Eigen::Vector2d::Zero());

}  // namespace litgs::host::frontend
