// A track's 3D point from known camera poses, the one triangulation of the engine (the front end's tracks
// and the refinement's re-triangulations). A consensus over candidate view pairs (the point most views
// agree with), a fit over the agreeing views, then filters on error, depth and angle.
//
// Two estimators, chosen per caller:
//  - kLinear (the front end): two-view DLT per pair, pairs by the widest observed ray angle, a DLT over the
//    agreeing views and Gauss-Newton steps on the pixel error.
//  - kMidpoint (the refinement): the point nearest to the rays in 3D, pairs spread over the views (first with
//    last, then inwards). With priors far from the truth (a constant 0.5 m offset) the midpoint lands
//    nearer to the LiDAR anchors the refinement gates on than the DLT does, and a wrong match cannot make
//    its pair look widest (docs/experiments.md, "one triangulator").
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

enum class TriangulationMethod { kLinear, kMidpoint };
enum class PairOrder { kWidestRayAngle, kSpreadOverViews };

struct TriangulationOptions {
  TriangulationMethod method = TriangulationMethod::kLinear;
  PairOrder pair_order = PairOrder::kWidestRayAngle;
  double max_error_px = 2.0;  // a view agrees when its reprojection error is below this
  // Views that must agree. 3 by default: with prior-guided matching every match already lies on its
  // epipolar line, so a two-view point triangulates with no error whether its match is right or wrong;
  // only a third view checks it.
  size_t min_views = 3;
  double min_angle_deg = 1.5;  // largest angle between the agreeing views' rays at the point
  double min_depth_m = 1e-3;   // in every agreeing view
  double max_depth_m = 1e4;
  int gauss_newton_iterations = 5;  // on the pixel error after the fit (the refinement's options: none)
  size_t max_pairs_tried = 40;      // candidate view pairs for the consensus
  void check() const;               // std::invalid_argument

  // The refinement's: kMidpoint, pairs spread over the track, 4 px, two views, 1 degree, 12 pairs.
  static TriangulationOptions refinement();
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

// The least-squares point nearest to the given views' rays; non-finite if degenerate.
Eigen::Vector3d triangulate_midpoint(const std::vector<TriangulationView>& views,
                                     const std::vector<size_t>& use);

}  // namespace litgs::host::frontend
