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
  // pixels). Like prior_epipolar_px it must cover the priors' error between the two frames, which grows
  // with the focal length in pixels: the default suits synth's odometry at 320x256 (docs/results.md).
  double max_transfer_px = 5;
  uint32_t cell_px = 4;  // z-buffer cell edge (pixels)
  uint32_t window = 1;   // cells on each side whose first surfaces are also candidates
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

// The smallest pixel distance from `to.px` of `from.px` lifted to one of its candidate depths and projected
// into `to`; nullopt where `from` has no candidate depth (the map cannot judge).
std::optional<double> lidar_transfer_px(const DepthView& from, const DepthView& to, const PinholeK& K);

// Whether the map contradicts the match: some direction could be judged and none transfers within bound.
bool contradicted_by_lidar(const DepthView& a, const DepthView& b, const PinholeK& K, double bound_px);

}  // namespace litgs::host::frontend
