// The bundle adjustment's own input and state, independent of any front end: frames with poses, points with
// their per-image observations and an optional anchor, the LiDAR plane each point is held to. A thin
// adapter fills it from a front end's tracks (or from synthetic_tracks.h for development and tests).
#pragma once

#include <Eigen/Core>
#include <Eigen/Geometry>
#include <cstdint>
#include <vector>

namespace litgs::host::refine {

// Pinhole intrinsics of undistorted observations; pixel centres at integer coordinates (OpenCV).
struct PinholeCamera {
  double fx = 1, fy = 1, cx = 0, cy = 0;
  int width = 0, height = 0;
};

// A camera pose T_world_cam: x_world = q_world_cam * x_cam + p_world_cam (p_world_cam: the camera centre).
struct CameraPose {
  double t_s = 0;
  Eigen::Quaterniond q_world_cam = Eigen::Quaterniond::Identity();
  Eigen::Vector3d p_world_cam = Eigen::Vector3d::Zero();
};

struct Observation {
  uint32_t frame = 0;
  Eigen::Vector2d uv = Eigen::Vector2d::Zero();  // pixels
  bool active = true;                            // false once rejected
  double weight = 1;                             // share of the frame's geometric weight (weights.h)
};

// A local LiDAR plane n . (x - l) = 0, |n| = 1.
struct PlaneRef {
  Eigen::Vector3d n = Eigen::Vector3d::UnitZ();
  Eigen::Vector3d l = Eigen::Vector3d::Zero();
};

struct TrackPoint {
  Eigen::Vector3d X = Eigen::Vector3d::Zero();  // world
  std::vector<Observation> obs;
  int anchor = -1;  // index into the anchors, or -1
  bool has_plane = false;
  PlaneRef plane;               // valid when has_plane
  bool plane_rejected = false;  // its plane residual was rejected: not associated again
  bool active = true;           // false: dropped (too few active observations, or not triangulable)
  size_t active_observations() const;
};

// A visual map point of the upstream estimator with its covariance (anchors.txt).
struct AnchorPoint {
  Eigen::Vector3d p_world = Eigen::Vector3d::Zero();
  Eigen::Matrix3d cov = Eigen::Matrix3d::Identity();  // m^2
};

}  // namespace litgs::host::refine
