// A calibration set for `calib intrinsics`: an asymmetric circle grid board (circles hotter or colder than
// the board) seen by the thermal camera from random poses about a metre away, rendered with the camera's
// sensor model (blur, vignetting, fixed-pattern and temporal noise, 16-bit counts) and, for a calibrated
// camera, through its lens distortion. `litgs-engine synth --preset circle-grid` writes it; the truth
// (intrinsics, each view's board pose) goes beside the images for the recovery figures.
#pragma once

#include <Eigen/Geometry>
#include <cstdint>
#include <filesystem>
#include <string>
#include <vector>

#include "host/synth/thermal_camera.h"
#include "host/synth/thermal_texture.h"

namespace litgs::host::synth {

struct CircleGridViewOptions {
  ThermalCameraOptions camera;  // width, height, hfov or a calibrated camera; the sensor's noise and blur
  CircleGridPattern grid;       // circles relative to the board's top-left corner (origin set here)
  bool hot_circles = true;      // false: the circles are colder than the board
  int views = 40;
  double min_distance_m = 0.7, max_distance_m = 1.4;  // board centre from the camera
  double max_tilt_deg = 35;                           // board normal from the viewing direction
  uint64_t seed = 1;
  std::string check() const;  // empty if valid, else the bad field
};

struct CircleGridView {
  io::Image raw;                  // 16-bit counts
  Eigen::Isometry3d T_cam_board;  // board frame: origin at the first circle, x along a row, y down rows
};

// The board's circle centres in its own frame, in OpenCV's order (row by row), metres.
std::vector<Eigen::Vector3d> circle_centres_on_board(const CircleGridPattern& grid);

// Views in which every circle projects inside the image with a margin of two radii (the board fully seen).
std::vector<CircleGridView> render_circle_grid_views(const CircleGridViewOptions& options, int threads);

// DIR/images/view_NNN.png (16-bit) and DIR/truth.json (the camera's intrinsics, the grid, each view's pose).
void write_circle_grid_set(const std::filesystem::path& dir, const CircleGridViewOptions& options,
                           int threads);

}  // namespace litgs::host::synth
