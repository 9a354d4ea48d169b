// `litgs-engine synth --preset circle-grid`: a calibration set for `calib intrinsics` instead of a scene. The
// policy of the preset lives here (the sensor's blur, the default view count and size, which synth options
// apply); the rendering is circle_grid_views.h.
#pragma once

#include <string>

#include "host/synth/circle_grid_views.h"
#include "host/synth/holed_board_views.h"
#include "host/synth/synth.h"

namespace litgs::host::synth {

inline constexpr const char* kCircleGridPreset = "circle-grid";

struct CalibrationSetReport {
  int views = 0;
  CircleGridPattern grid;
  int width = 0, height = 0;
  bool distorted = false;  // rendered through --rig's lens distortion
};

// Writes OUT/images and OUT/truth.json for `options` (preset circle-grid): `frames` views (default 40) at
// width x height (default 320x256), or through --rig's thermal camera (its intrinsics and distortion, scaled
// to width x height if given), with hot or cold circles. std::invalid_argument for an option a calibration
// set has no use for (--drift, --frame-rate, --appearance, --lidar-holdout-every), a bad value, or a
// non-empty OUT without --force (--force replaces images/ and truth.json only).
CalibrationSetReport generate_calibration_set(const SynthOptions& options, bool hot_circles);

struct HoledBoardSetReport {
  int views = 0;
  int width = 0, height = 0;
  bool rig = false;  // the camera and T_cam_lidar from --rig's file
};

// Writes OUT/images, OUT/scans, OUT/board.yaml, OUT/camera.yaml and OUT/truth.json for `options` (preset
// holed-board): `frames` views (default 40) at width x height (default 320x256), or through --rig's thermal
// camera with its "Extrinsic [to LIDAR]" as the rig. The same refusals as generate_calibration_set (--force
// replaces those five entries only).
HoledBoardSetReport generate_holed_board_set(const SynthOptions& options);

}  // namespace litgs::host::synth
