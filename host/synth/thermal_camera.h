// The thermal camera: pinhole ray casting of the world's radiance, then the sensor: vignetting, fixed-
// pattern and temporal noise, 16-bit raw counts; and the 8-bit automatic-gain view of a raw frame.
// Camera frame: x right, y down, z forward (OpenCV).
#pragma once

#include <Eigen/Core>
#include <Eigen/Geometry>
#include <cstdint>
#include <optional>
#include <string>

#include "host/synth/geometry.h"
#include "io/image.h"
#include "io/scene_types.h"

namespace litgs::host::synth {

struct ThermalCameraOptions {
  int width = 320;       // pixels
  int height = 256;      // pixels
  double hfov_deg = 50;  // horizontal field of view; fx = fy, principal point at the centre
  // A calibrated camera instead (e.g. from M2DGR's file, host/synth/m2dgr_rig.h): its intrinsics and lens
  // distortion replace width, height and hfov_deg; the frames are rendered through the distortion.
  std::optional<io::CameraIntrinsics> calibrated;
  double temporal_noise_raw = 3;    // per pixel and frame (standard deviation, counts)
  double fixed_pattern_raw = 2;     // per pixel, the same in every frame (residual non-uniformity)
  double vignetting_raw = 60;       // counts lost at the image corners (quadratic in the radius)
  double column_noise_raw = 0;      // per column, the same in every frame (the readout's column pattern)
  double blur_px = 0;               // the optics' blur: Gaussian sigma in pixels (0: none)
  double agc_low_percentile = 1;    // 8-bit view: this percentile maps to 0
  double agc_high_percentile = 99;  // and this one to 255

  std::string check() const;  // empty if valid, else the first bad field and why
  io::CameraIntrinsics intrinsics() const;
};

// The noise-free radiance along the ray through pixel (x, y) (pixel centres at integers), through K's lens
// distortion; the sky's where the lens model has no ray.
double pixel_radiance(const World& world, const io::CameraIntrinsics& K, const Eigen::Isometry3d& T_world_cam,
                      double x, double y);

// A 16-bit raw frame. Noise is a pure function of (seed, frame_index, pixel): rows may be rendered by
// `threads` threads in any order and the bytes do not change.
io::Image render_thermal(const World& world, const ThermalCameraOptions& options,
                         const Eigen::Isometry3d& T_world_cam, uint64_t seed, uint64_t frame_index,
                         int threads);

// The true depth of every pixel centre (through K's lens distortion): z along the camera's axis in
// millimetres (16-bit, rounded), 0 where the ray meets nothing (sky) or the depth exceeds 65.535 m. The
// scene's gt/depth/<frame>.png.
io::Image true_depth_mm(const World& world, const io::CameraIntrinsics& K,
                        const Eigen::Isometry3d& T_world_cam);

// The 8-bit automatic-gain view: a per-frame percentile stretch of the raw counts.
io::Image auto_gain_8bit(const io::Image& raw, const ThermalCameraOptions& options);

}  // namespace litgs::host::synth
