// A real sensor rig for the synthetic scenes: the thermal camera (intrinsics, lens distortion, extrinsic) and
// the IMU's lever arm read from M2DGR's calibration file, in place of a preset's own rig, so that a scene
// can be written out as a bag that `import bag` reads with that same file (docs/scene-format.md).
#pragma once

#include <filesystem>
#include <optional>
#include <string>

#include "host/synth/presets.h"

namespace litgs::host::synth {

struct M2dgrRig {
  std::filesystem::path file;                // M2DGR's calibration_results.txt
  std::string camera_block = "Cam-thermal";  // the camera to simulate
  std::string imu_block = "Handsfree IMU";   // the IMU the body (and poses) follow
};

// Replaces p's T_imu_cam, T_imu_lidar and camera intrinsics by the file's. The body frame stays the IMU:
// T_imu_lidar = inverse(T_lidar_imu) and T_imu_cam = T_imu_lidar * T_lidar_cam, each "Extrinsic [to LIDAR]".
// width and height (both or neither) scale the calibrated camera to another image size; by default the
// file's. io::IoError on an unreadable file or block; std::invalid_argument when a block lacks what it needs.
void apply_m2dgr_rig(const M2dgrRig& rig, std::optional<int> width, std::optional<int> height, Preset& p);

}  // namespace litgs::host::synth
