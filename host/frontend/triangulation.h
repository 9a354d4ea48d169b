// A track's 3D point from known camera poses: two-view linear triangulation over candidate view pairs (the
// robust choice: the pair whose point most views agree with), a linear fit over the agreeing views, a few
// Gauss-Newton steps on the pixel reprojection error, then filters on error, angle and depth.
#pragma once

#include <Eigen/Core>
#include <cstddef>
#include <vector>

namespace litgs::host::frontend {

struct TriangulationView {
  Eigen::Matrix3d R_cam_world = Eigen::Matrix3d::Identity();  // x_cam = R x_world + t
  Eigen::Vector3d t_cam_world = Eigen::Vector3d::Zero();
  Eigen::Vector2d xy = Eigen::Vector2d::Zero();  // normalized undistorted image coordinates (x/z, y/z)
};

struct TriangulationOptions {
  double max_error_px = 2.0;  // a view agrees when its reprojection error is below this
  // Views that must agree. 3 by default: with prior-guided matching every match already lies on its
  // epipolar line, so a two-view point triangulates with no error whether its match is right or wrong;
  // only a third view checks it.
  size_t min_views = 3;
  double min_angle_deg = 1.5;  // largest angle between the agreeing views' rays at the point
  double min_depth_m = 1e-3;   // in every agreeing view
  double max_depth_m = 1e4;
  int gauss_newton_iterations = 5;
  size_t max_pairs_tried = 40;  // candidate view pairs for the robust choice (widest baselines first)
  void check() const;           // std::invalid_argument
};

enum class TriangulationOutcome { kOk, kTooFewViews, kNoAngle, kBadDepth, kLargeError };

struct TriangulatedPoint {
  TriangulationOutcome outcome = TriangulationOutcome::kTooFewViews;
  Eigen::Vector3d xyz = Eigen::Vector3d::Zero();  // finite whenever outcome is kOk
  std::vector<size_t> views;                      // indices of the agreeing views (the track length)
  double mean_error_px = 0;
};

// fx, fy turn normalized errors into pixels. Never returns a non-finite point as kOk.
TriangulatedPoint triangulate(const std::vector<TriangulationView>& views, double fx, double fy,
                              const TriangulationOptions& options);

// Linear (DLT) triangulation from the given views; non-finite if degenerate.
Eigen::Vector3d triangulate_linear(const std::vector<TriangulationView>& views,
                                   const std::vector<size_t>& use);

}  // namespace litgs::host::frontend
