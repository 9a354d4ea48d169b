// A calibration set for `calib extrinsic`: a flat board with circular holes held in front of a static rig
// (a spinning LiDAR and the thermal camera) at random poses, seen by both. The camera renders it with its
// sensor model (the board warmer than the wall and ground seen through the holes); the LiDAR scans it with
// range noise and a beam divergence that widens the board at its edges. `litgs-engine synth --preset
// holed-board` writes it; the truth (T_cam_lidar, each view's board pose) goes beside it.
#pragma once

#include <Eigen/Geometry>
#include <filesystem>
#include <string>
#include <vector>

#include "calib/holed_board.h"
#include "host/synth/lidar_sim.h"
#include "host/synth/thermal_camera.h"

namespace litgs::host::synth {

inline constexpr const char* kHoledBoardPreset = "holed-board";

struct HoledBoardViewOptions {
  ThermalCameraOptions camera;
  LidarOptions lidar = velodyne_like();
  calib::HoledBoard board;  // as calib extrinsic reads it from board.yaml
  // The rig: the camera's pose in the LiDAR frame (LiDAR x forward, y left, z up; camera z forward).
  Eigen::Isometry3d T_lidar_cam = default_rig();
  int views = 40;
  double min_distance_m = 1.8, max_distance_m = 3.5;  // board centre from the camera
  double max_tilt_deg = 30;                           // board normal from the line of sight
  uint64_t seed = 1;

  std::string check() const;  // empty if valid, else the bad field
  // A VLP-32C-like spinning LiDAR: 32 rings over -25..+15 degrees (evenly spaced here), 0.2 degree steps,
  // 1 cm range noise, 3 mrad beam divergence.
  static LidarOptions velodyne_like();
  // The camera 8 cm below and 10 cm to the right of the LiDAR, looking along its x, turned by a few degrees.
  static Eigen::Isometry3d default_rig();
};

struct HoledBoardView {
  io::Image raw;                      // 16-bit counts
  std::vector<Eigen::Vector3d> scan;  // the LiDAR's returns, LiDAR frame
  Eigen::Isometry3d T_cam_board = Eigen::Isometry3d::Identity();
};

// Views in which the whole board lies in the image (5 px margin) and within the LiDAR's rings.
std::vector<HoledBoardView> render_holed_board_views(const HoledBoardViewOptions& options, int threads);

// DIR/images/view_NNN.png (16-bit), DIR/scans/view_NNN.pcd, DIR/board.yaml, DIR/camera.yaml (the true
// intrinsics, as `calib intrinsics` writes them) and DIR/truth.json (T_cam_lidar, each view's board pose).
void write_holed_board_set(const std::filesystem::path& dir, const HoledBoardViewOptions& options,
                           int threads);

}  // namespace litgs::host::synth
