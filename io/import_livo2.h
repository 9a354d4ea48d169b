// `litgs-engine import livo2`: a FAST-LIVO2 output folder plus its configuration into a scene directory
// (docs/scene-format.md, "Importing from FAST-LIVO2").
//
// FAST-LIVO2 (hku-mars/FAST-LIVO2) writes, under its Log/ folder:
//   result/<seq_name>.txt   TUM poses of the IMU (its state: rot_end, pos_end = T_world_imu), at the LIO
//                           update times, which in LIVO mode are the (offset-corrected) image times
//   pcd/*.pcd               the world-frame map: all_raw_points.pcd and/or all_downsampled_points.pcd
//                           (interval -1), or one file per batch of scans
//   image/<t>.png           frames named by their time with 6 decimals (the images the VIO used, after
//                           its `scale` resize)
// and reads, from its ROS parameters (one or several YAML files):
//   camera: cam_model (Pinhole), cam_width, cam_height, [scale], cam_fx, cam_fy, cam_cx, cam_cy,
//           cam_d0..cam_d3 (k1 k2 p1 p2), [cam_d4] (k3)
//   extrin_calib: extrinsic_R (9, row-major), extrinsic_T (3): the LiDAR in the IMU frame, T_imu_lidar
//                 (FAST-LIO's convention: p_imu = R p_lidar + T);
//                 Rcl (9, row-major), Pcl (3): LiDAR points into the camera frame, T_cam_lidar.
#pragma once

#include <Eigen/Core>
#include <filesystem>
#include <optional>
#include <string>
#include <vector>

namespace litgs::io {

struct Livo2ImportOptions {
  std::filesystem::path log;  // FAST-LIVO2's Log/ folder (holding result/, pcd/, image/)
  // YAML files to search for the camera keys (cam_fx, ...) and the extrinsics (extrinsic_R, Rcl, ...):
  // the main config and the camera config, at any nesting (ROS 1 namespaces, ROS 2 ros__parameters).
  std::vector<std::filesystem::path> config;
  std::filesystem::path out;         // scene directory to write (created; must not hold other frames)
  std::filesystem::path trajectory;  // TUM file; default: the one .txt under log/result
  std::filesystem::path map;         // PCD file; default: see import_livo2
  // Recentring offset subtracted from world positions; default zero (FAST-LIVO2's world is the first IMU
  // frame, near the origin).
  std::optional<Eigen::Vector3d> world_offset_m;
  std::string image_extension = ".png";  // of the written frames: ".png" or ".tiff"
  // An image takes the trajectory pose whose time is within this of its own (FAST-LIVO2 prints both with
  // 6 decimals); others are interpolated. Seconds, >= 0.
  double pose_snap_s = 1e-6;
  // Extrinsic rotations printed with few digits are orthonormalized (nearest rotation) if they are off by
  // at most this (Frobenius norm of R^T R - I); more is an error.
  double max_rotation_error = 1e-2;

  // Throws std::invalid_argument naming the bad field.
  void check() const;
};

struct Livo2ImportReport {
  size_t frames = 0;               // images written with a camera pose
  size_t skipped_no_pose = 0;      // images outside the trajectory
  size_t map_points = 0;           // points of lidar/map.pcd
  std::vector<std::string> notes;  // conversions a user should know about
};

// Converts and writes the scene:
// - camera poses T_world_cam = T_world_imu(t) * T_imu_lidar * inverse(T_cam_lidar) at each image time t
//   (the image's name), poses_frame: camera; images outside the trajectory are left out (counted);
// - intrinsics from the camera keys, multiplied by `scale` (as FAST-LIVO2's vikit camera loader does);
//   distortion k1 k2 p1 p2 [k3] (OpenCV radtan); only cam_model Pinhole;
// - T_cam_lidar and T_imu_lidar as configured; time offset 0 (FAST-LIVO2 has already moved image stamps
//   into the LiDAR/IMU clock by img_time_offset);
// - the map: options.map, else log/pcd/all_downsampled_points.pcd, else all_raw_points.pcd, else every
//   .pcd of log/pcd merged (positions, and intensity if all have it), written as lidar/map.pcd;
// - images: 8/16-bit PNG/TIFF, colour frames with equal channels become one channel (single_channel).
// IoError naming the file (and line) on a missing or malformed input, an unsupported cam_model, a
// non-rotation extrinsic, an image whose size disagrees with the camera, no image with a pose.
Livo2ImportReport import_livo2(const Livo2ImportOptions& options);

}  // namespace litgs::io
