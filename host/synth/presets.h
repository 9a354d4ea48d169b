// The named synthetic scenes: the world, the rig (extrinsics), the motion and every sensor's options.
#pragma once

#include <Eigen/Geometry>
#include <string>
#include <vector>

#include "host/synth/estimator_model.h"
#include "host/synth/geometry.h"
#include "host/synth/imu_sim.h"
#include "host/synth/lidar_sim.h"
#include "host/synth/thermal_camera.h"
#include "host/synth/trajectory.h"

namespace litgs::host::synth {

// When the camera runs its non-uniformity correction it repeats the previous frame exactly.
struct NucOptions {
  int first_min = 5, first_max = 14;         // frame index range of the first freeze
  int interval_min = 20, interval_max = 40;  // frames between freezes
  int length_max = 2;                        // frozen frames per freeze: 1..length_max

  std::string check() const;  // empty if valid, else the first bad field and why
};

struct Preset {
  std::string name;
  std::string description;
  World world;
  TrajectoryOptions trajectory;                                   // of the body (= IMU) frame
  Eigen::Isometry3d T_imu_cam = Eigen::Isometry3d::Identity();    // maps camera points into the IMU frame
  Eigen::Isometry3d T_imu_lidar = Eigen::Isometry3d::Identity();  // maps LiDAR points into the IMU frame
  ThermalCameraOptions camera;
  LidarOptions lidar;
  ImuOptions imu;
  EstimatorNoiseOptions estimator;
  NucOptions nuc;
  double frame_rate_hz = 10;  // camera frames and LiDAR scans (same stamps)
  int frames = 60;            // default frame count
  int max_frames = 300;       // beyond this the rig would leave the modelled world
  double map_voxel_m = 0.1;   // voxel of the downsampled LiDAR map
};

// How the surfaces look to the thermal camera. kTextured (the default): weathering at several scales,
// per-brick and per-panel spread, rain streaks, heat bleeding around openings, optics blur and column noise,
// calibrated against real long-wave frames (docs/synthetic-appearance.md). kFlat: the smooth blocks of
// earlier versions (uniform walls, faint joints), on which a feature detector finds little.
enum class Appearance { kTextured, kFlat };
Appearance parse_appearance(const std::string& name);  // "textured" | "flat"; invalid_argument otherwise
std::string appearance_name(Appearance appearance);

// The preset names, the default first.
std::vector<std::string> preset_names();

// The preset `name` (std::invalid_argument listing the valid names otherwise). The seed varies the
// textures' noise and the rig's small calibration offsets; the layout is fixed per preset.
Preset make_preset(const std::string& name, uint64_t seed, Appearance appearance = Appearance::kTextured);

}  // namespace litgs::host::synth
