// Thermal intrinsics from circle-grid views (Zhang's method through OpenCV's calibrateCamera, or
// cv::fisheye for the equidistant model): views whose reprojection error is an outlier are left out and the
// camera is calibrated again; the result carries each parameter's standard deviation, every view's error
// and how much of the image the detections covered.
#pragma once

#include <cstddef>
#include <string>
#include <vector>

#include "calib/circle_grid.h"
#include "io/scene_types.h"

namespace litgs::calib {

struct IntrinsicsOptions {
  io::CameraModel model = io::CameraModel::kPinhole;  // pinhole: k1 k2 p1 p2; equidistant: k1..k4
  size_t min_views = 5;
  // A view is left out when its RMS error exceeds median + outlier_k 1.4826 MAD of all views' (and 0.5 px).
  double outlier_k = 3;
  void check() const;
};

// One image: its name, size and detection.
struct CalibrationView {
  std::string name;
  int width = 0, height = 0;
  GridDetection detection;
};

struct ViewReport {
  std::string name;
  bool used = false;
  double rms_px = -1;  // -1: not calibrated with (no grid, other size)
  std::string note;    // why it was not used
};

struct IntrinsicsResult {
  io::CameraIntrinsics camera;
  double rms_px = 0;              // over the views used
  std::vector<double> stddev;     // fx fy cx cy then the distortion coefficients (pinhole only; else empty)
  std::vector<ViewReport> views;  // every view, in input order
  size_t views_used = 0;
  double coverage = 0;             // share of a 8x8 grid of image cells holding a detected centre
  std::vector<std::string> notes;  // e.g. image corners without detections
};

// std::invalid_argument when fewer than min_views images show the grid at the set's size, naming how many
// did and why the others did not.
IntrinsicsResult calibrate_intrinsics(const std::vector<CalibrationView>& views, const CircleGrid& grid,
                                      const IntrinsicsOptions& options);

}  // namespace litgs::calib
