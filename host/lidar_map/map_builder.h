// The LiDAR map of a scene that has only scans: every scan point deskewed by its own time, placed in the
// world with the trajectory and the extrinsics, averaged per voxel, then given a local plane fit (normal and
// planarity). Behind `litgs-engine map` and `import bag` (docs/lidar-map.md).
#pragma once

#include <Eigen/Core>
#include <filesystem>
#include <functional>
#include <optional>
#include <string>
#include <vector>

#include "host/train/lidar_planes.h"
#include "io/point_cloud.h"
#include "io/scene.h"

namespace litgs::host {

struct LidarMapOptions {
  double voxel_m = 0.1;      // edge of the averaging voxel
  double min_range_m = 0.5;  // returns nearer than this (the rig itself) are dropped
  double max_range_m = 100;  // and farther than this (sparse, noisy)
  bool deskew = true;        // use the scans' per-point "time" field where they have one
  int deskew_samples = 8;    // poses sampled across one scan's time span, interpolated between
  PlaneFitOptions planes;    // the per-point plane fit on the voxel centroids
  // Scans 0, N, 2N, ... stay out of the map and go into lidar/heldout.pcd, so that geometry and the
  // refinement's scan check meet measurements the map never held (0: every scan in the map). Scenes with
  // fewer than 2N scans hold none out.
  int holdout_every = io::kDefaultLidarHoldoutEvery;
  void check() const;  // throws std::invalid_argument naming the bad field
};

struct LidarMapReport {
  size_t scans = 0;               // scans used
  size_t scans_without_pose = 0;  // outside the trajectory: skipped
  size_t scans_deskewed = 0;      // with a per-point time field
  size_t scans_heldout = 0;       // left out of the map (write_scene_lidar_map): in lidar/heldout.pcd
  size_t heldout_points = 0;      // points of the held-out map
  size_t input_points = 0;        // in range, over the scans used
  size_t map_points = 0, planar_points = 0;
  double seconds = 0;
  double peak_rss_mb = 0;  // the process's peak resident memory (VmHWM) when the map was done
  std::vector<std::string> notes;
};

// T_world_lidar at a LiDAR-clock time, or nullopt outside the trajectory.
using LidarPoseAt = std::function<std::optional<Eigen::Matrix4d>(double t_lidar_s)>;

// The scene's LiDAR pose: poses.txt interpolated (camera poses at t_lidar - time_offset_cam_lidar_s, IMU
// poses, on the LiDAR clock, at t_lidar), times T_cam_lidar or T_imu_lidar.
LidarPoseAt scene_lidar_pose(const io::Scene& scene);
// The same through another trajectory in the frame and on the clock scene.yaml gives poses.txt (refine's
// prior and refined poses); `poses` must outlive the returned function.
LidarPoseAt scene_lidar_pose(const io::SceneConfig& config, const std::vector<io::TumPose>& poses);

// The key of the map voxel (edge voxel_m) that holds p: 21 bits per axis, so +-2^20 voxels; a point beyond
// them is a std::invalid_argument that names it.
uint64_t voxel_key(const Eigen::Vector3d& p, double voxel_m);

// One scan's points in range, each placed in the world with the pose at its own time (deskewed where the
// scan has a "time" field and options.deskew), and the index of each in the scan. Empty when the stamp
// lies outside the trajectory.
struct PlacedScan {
  std::vector<Eigen::Vector3d> world;
  std::vector<size_t> index;
  bool deskewed = false;
};
PlacedScan place_scan(const io::PointCloud& scan, double t_stamp_s, const LidarPoseAt& T_world_lidar,
                      const LidarMapOptions& options);

// The map from scans given one at a time (sensor frame; an extra field "time" holds each point's seconds
// after the scan's stamp). Output: world positions, mean intensity where every scan has one, unit normals
// where planar (zero elsewhere), and the extra field "planarity" = 1 - smallest/middle eigenvalue of the
// neighbourhood (0 where no fit). Points sorted by voxel: same input, same map.
io::PointCloud build_lidar_map(const std::vector<double>& scan_times_s,
                               const std::function<io::PointCloud(size_t)>& scan,
                               const LidarPoseAt& T_world_lidar, const LidarMapOptions& options,
                               LidarMapReport& report);

// Reads the scene's scans and trajectory, builds the map and writes it: to `out` when given (scene.yaml
// untouched; the held-out scans' map beside it as <out stem>.heldout.pcd), else to lidar/map.pcd and
// lidar/heldout.pcd with scene.yaml's lidar_map and lidar_holdout_every set. An existing lidar/map.pcd is
// kept unless `replace`. std::invalid_argument naming the problem (no scans, no scan within the trajectory,
// a map already there); io::IoError on file errors.
LidarMapReport write_scene_lidar_map(const std::filesystem::path& scene_dir, const LidarMapOptions& options,
                                     const std::filesystem::path& out = {}, bool replace = false);

// The process's peak resident set size in MB (Linux /proc/self/status VmHWM; 0 where unknown).
double peak_rss_mb();

}  // namespace litgs::host
