// Geometric verification of a pair's matches: a robust essential-matrix fit (OpenCV USAC, MAGSAC++, with
// the known intrinsics) and, where prior poses exist, a bound on the distance to the prior's epipolar line.
#pragma once

#include <Eigen/Core>
#include <array>
#include <cstdint>
#include <optional>
#include <vector>

#include "io/scene_types.h"
#include "io/sfm_files.h"

namespace litgs::host::frontend {

// The scene camera's distortion removed: pixel coordinates of the ideal pinhole with the same fx fy cx cy.
std::vector<Eigen::Vector2d> undistort_keypoints(const io::CameraIntrinsics& camera,
                                                 const std::vector<io::SfmKeypoint>& keypoints);

struct VerifyOptions {
  double max_error_px = 1.5;  // MAGSAC's threshold (pixels of the undistorted image)
  double confidence = 0.999;  // OpenCV's defaults
  int max_iterations = 1000;
  // Matches farther than this from the prior's epipolar line (both ways, undistorted pixels) are rejected.
  // It must cover the priors' error: a few pixels for Metashape/COLMAP poses, more for a drifting odometry.
  double prior_epipolar_px = 8;
  size_t min_inliers = 15;  // fewer verified matches: the pair is rejected (every flag false)
  void check() const;       // std::invalid_argument
};

// Relative prior pose of b with respect to a: x_b = R_ba x_a + t_ba (camera frames).
struct RelativePose {
  Eigen::Matrix3d R_ba = Eigen::Matrix3d::Identity();
  Eigen::Vector3d t_ba = Eigen::Vector3d::Zero();
};

struct PinholeK {
  double fx = 1, fy = 1, cx = 0, cy = 0;
};

struct Verification {
  std::vector<uint8_t> inlier;  // per match
  size_t inliers = 0;
  size_t rejected_by_prior = 0;  // matches beyond prior_epipolar_px
  bool verified = false;         // inliers >= min_inliers
};

// ua, ub: undistorted pixel coordinates of each image's keypoints; matches index them.
Verification verify_pair(const std::vector<Eigen::Vector2d>& ua, const std::vector<Eigen::Vector2d>& ub,
                         const std::vector<std::array<uint32_t, 2>>& matches, const PinholeK& K,
                         const std::optional<RelativePose>& prior, const VerifyOptions& options);

// Pixel distance of the match from the prior's geometry: the larger of the two epipolar-line distances;
// for a prior without baseline (pure rotation) the distance of xb from the rotated xa.
double prior_distance_px(const Eigen::Vector2d& xa, const Eigen::Vector2d& xb, const PinholeK& K,
                         const RelativePose& prior);

// For each keypoint of a, the keypoints of b within `bound_px` of it by prior_distance_px: the candidates
// prior-guided matching compares descriptors for (b's keypoints are bucketed so a line visits few).
std::vector<std::vector<uint32_t>> prior_candidates(const std::vector<Eigen::Vector2d>& ua,
                                                    const std::vector<Eigen::Vector2d>& ub, const PinholeK& K,
                                                    const RelativePose& prior, double bound_px);

}  // namespace litgs::host::frontend
