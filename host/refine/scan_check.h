// The LiDAR side of the guard against a refinement that makes the poses worse (holdout_guard.h holds the
// image side): scans the map left out (scene.yaml lidar_holdout_every), taken through the prior and
// through the refined trajectories, each against the local planes of the map that trajectory builds from
// the other scans. Camera poses that the images like but that put the LiDAR's own measurements off the
// surfaces its other scans measured are worse poses.
#pragma once

#include <Eigen/Core>
#include <string>
#include <vector>

#include "host/train/lidar_planes.h"

namespace litgs::host::refine {

struct ScanCheckOptions {
  // Scans 0, N, 2N, ... where the scene holds none out of its map (an older scene: those scans are then
  // in the map, a weaker check); 0: no check. A scene's own held-out scans take precedence.
  size_t every = 8;
  size_t points_per_scan = 3000;  // evenly subsampled
  double max_distance_m = 0.3;    // points farther than this from every map plane (either way) are left out
  double tolerance = 0.02;        // refined poses pass when their mean distance <= (1 + tolerance) * priors'
  void check() const;             // std::invalid_argument naming the field
};

// One checked scan: its points in the LiDAR frame, and the LiDAR's pose at its stamp through each
// trajectory.
struct CheckedScan {
  std::vector<Eigen::Vector3d> points_lidar;
  Eigen::Matrix4d T_world_lidar_prior = Eigen::Matrix4d::Identity();
  Eigen::Matrix4d T_world_lidar_refined = Eigen::Matrix4d::Identity();
};

struct ScanVerdict {
  size_t scans = 0, points = 0;                 // points within max_distance_m under both pose sets
  double prior_mean_m = 0, refined_mean_m = 0;  // mean point-to-plane distance
  bool measured = false;                        // at least one point
  bool keep_refined = true;  // false: the refined poses put the scans farther from their map's planes
  std::string summary;       // one line for the report
};

// Each scan through the priors against `prior_map`, through the refined poses against `refined_map` (the
// same map twice: both against one map).
ScanVerdict judge_on_scans(const PlanarMap& prior_map, const PlanarMap& refined_map,
                           const std::vector<CheckedScan>& scans, const ScanCheckOptions& options);

}  // namespace litgs::host::refine
