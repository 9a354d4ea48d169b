// The LiDAR side of the guard against a refinement that makes the poses worse (holdout_guard.h holds the
// image side): the scans of every Nth frame, taken through the prior and through the refined camera poses
// (T_world_cam * T_cam_lidar), against the local planes of the LiDAR map. Camera poses that the images
// like but that put the LiDAR's own measurements off the map's surfaces are worse poses.
#pragma once

#include <Eigen/Core>
#include <string>
#include <vector>

#include "host/refine/ba_types.h"
#include "host/train/lidar_planes.h"

namespace litgs::host::refine {

struct ScanCheckOptions {
  size_t every = 8;               // the scans of frames 0, N, 2N, ...; 0: no check
  size_t points_per_scan = 3000;  // evenly subsampled
  double max_distance_m = 0.3;    // points farther than this from every map plane (either way) are left out
  double tolerance = 0.02;        // refined poses pass when their mean distance <= (1 + tolerance) * priors'
  void check() const;             // std::invalid_argument naming the field
};

// One checked scan: the frame it belongs to and its points in the LiDAR frame.
struct CheckedScan {
  size_t frame = 0;
  std::vector<Eigen::Vector3d> points_lidar;
};

struct ScanVerdict {
  size_t scans = 0, points = 0;                 // points within max_distance_m under both pose sets
  double prior_mean_m = 0, refined_mean_m = 0;  // mean point-to-plane distance
  bool measured = false;                        // at least one point
  bool keep_refined = true;  // false: the refined poses put the scans farther from the map's planes
  std::string summary;       // one line for the report
};

ScanVerdict judge_on_scans(const PlanarMap& map, const std::vector<CheckedScan>& scans,
                           const std::vector<CameraPose>& priors, const std::vector<CameraPose>& refined,
                           const Eigen::Matrix4d& T_cam_lidar, const ScanCheckOptions& options);

}  // namespace litgs::host::refine
