// One Ceres solve of the LiDAR-plane-constrained bundle adjustment (docs/refinement.md). Variables: the
// camera poses (unit quaternion on Ceres' quaternion manifold, position) of the frames marked variable,
// and the points seen by them. Residuals, each with a robust loss:
// - reprojection, in pixels (Cauchy, scale pixel_loss_px), scaled by the observation's weight;
// - the signed point-to-plane distance n . (X - l) / plane_sigma_m of a point associated with a LiDAR
//   plane (a signed residual, differentiable at zero), scaled by the point's weight; Cauchy at 1 sigma:
//   round 1 associates through the drifting priors, and a point held to the wrong plane must lose its
//   pull rather than keep the Huber's constant one (that mended a synthetic street seed the Huber had left
//   far off: docs/refinement.md, "Why the anchors hurt");
// - relative-pose priors between consecutive frames from the odometry (the priors' relative motion; sigma
//   grows with the distance travelled), which keep metric scale, and a prior on the first frame's
//   pose at the odometry's own per-frame accuracy (the map and the odometry share their first frame), which
//   holds the gauge where planes do not (along a street, translation along it); Cauchy loss at 1 sigma, so
//   that priors offset from the map as a whole (a false statement of that accuracy) give way to the planes;
// - anchor position priors L^-1 (X - a) with the anchor's (guarded) covariance Sigma = L L^T, Cauchy loss
//   at 1 sigma: a wrongly associated anchor (a neighbouring track) loses its pull instead of keeping the
//   constant pull of a Huber loss.
// Ceres stays inside bundle_adjustment.cc.
#pragma once

#include <string>
#include <vector>

#include "host/refine/ba_types.h"
#include "host/refine/scan_alignment.h"

namespace litgs::host::refine {

struct BaWeights {
  // Cauchy scale of the reprojection residual. 1 px: the front end's own tracks scatter about 0.8 px RMS
  // about the truth (ci/match-truth's track consistency); a wrong keypoint 2.5 px off keeps 39 % of a good
  // one's pull at 2 px, 14 % at 1 px. At 1 px the synthetic facade's and street's refined ATE fell
  // (docs/experiments.md, issue 44).
  double pixel_loss_px = 1;
  double plane_sigma_m = 0.02;      // point-to-plane: residual = distance / sigma
  double anchor_loss = 1;           // Cauchy scale of the whitened anchor residual
  double rel_sigma_t_m = 0.01;      // relative-pose prior: translation sigma ...
  double rel_sigma_t_per_m = 0.02;  // ... plus this per metre travelled between the frames
  // Rotation sigma between consecutive frames: an odometry's relative rotation comes from its gyro over
  // one frame interval and is far better than any frame's absolute orientation (gauge_sigma_r_rad); at
  // 3 mrad a sideways shift of the camera traded against a small rotation cost almost nothing, and the
  // tighter prior lowered the synthetic facade's ATE (docs/refinement.md, "Why the anchors hurt"; issue 14).
  // With the front end's own tracks the poses jittered by a pitch traded against a height, which a camera
  // facing a flat wall cannot tell apart; 0.3 mrad, the per-frame orientation noise of the estimator that
  // synth models, steadied them on every preset and on DUNR's control points (docs/experiments.md, "Issue
  // 44 on the engine's own tracks, continued").
  double rel_sigma_r_rad = 0.0003;
  double rel_sigma_r_per_m = 0.002;  // ... plus this per metre travelled
  // An odometry's orientation is absolute up to a slow drift (gravity fixes roll and pitch; yaw drifts with
  // distance): every frame gets an orientation prior of this sigma plus the per-metre term times the
  // distance from the first frame. Without it the images and planes leave a rotation of the whole
  // trajectory nearly free, and the refined orientations drifted further from the truth than the priors'
  // while the SE(3)-aligned ATE hid it (docs/experiments.md, "the refinement on the engine's own tracks",
  // issue 44). 0: off.
  double odometry_sigma_r_rad = 0.002;
  double odometry_sigma_r_per_m = 0.0005;
  // Position likewise: the LiDAR map is in the odometry's frame, so a camera pose may move from its prior
  // by the drift but not slide freely. Without it a direction that the planes in view do not constrain
  // (up along a facade with little ground in the tracks) is held only by the first frame, and the refined
  // trajectory slid off the map while the SE(3)-aligned ATE improved (docs/experiments.md, "Figures moved
  // out of code comments"). 0: off.
  double odometry_sigma_t_m = 0.02;
  double odometry_sigma_t_per_m = 0.02;
  // LiDAR scan points held to the planes of the map the current poses build (scan_alignment.h): residual
  // distance / sigma, Cauchy at 1, times scan_weight.
  double scan_sigma_m = 0.02;
  double scan_weight = 1;
  double gauge_sigma_t_m = 0.01;     // the first frame's pose prior: the odometry's per-frame accuracy
  double gauge_sigma_r_rad = 0.003;  // (translation as rel_sigma_t_m)
  // Priors that are absolute (a georeferenced photogrammetric solution such as Metashape's, not an
  // odometry): every frame, not only the first, gets the gauge prior.
  bool absolute_priors = false;
};

struct BaProblem {
  PinholeCamera camera;
  std::vector<CameraPose>* poses = nullptr;                // refined in place
  const std::vector<CameraPose>* priors = nullptr;         // the odometry's poses, same frames
  std::vector<TrackPoint>* points = nullptr;               // refined in place
  const std::vector<AnchorPoint>* anchors = nullptr;       // null: no anchor priors
  std::vector<Eigen::Matrix3d> anchor_sqrt_information;    // L^-1 per anchor (when anchors)
  const std::vector<ScanPlaneLink>* scan_links = nullptr;  // null: no scan term
  std::vector<bool> variable;                              // per frame; empty: all
  bool use_planes = true, use_anchor_priors = true;
  BaWeights weights;
  int threads = 1;
  int max_iterations = 50;
};

struct BaSolveSummary {
  double initial_cost = 0, final_cost = 0;
  int iterations = 0;
  size_t reprojection_residuals = 0, plane_residuals = 0, prior_residuals = 0, anchor_residuals = 0,
         scan_residuals = 0;
  size_t points = 0, variable_frames = 0;
  bool usable = false;      // Ceres' verdict on the solution
  std::string termination;  // CONVERGENCE, NO_CONVERGENCE, ...
  std::string brief;        // Ceres' BriefReport()
  double seconds = 0;
};

BaSolveSummary solve_bundle_adjustment(BaProblem& problem);

// The reprojection error of x seen from `pose` at `uv`, pixels (infinity when behind the camera).
double reprojection_error_px(const CameraPose& pose, const PinholeCamera& camera, const Eigen::Vector3d& x,
                             const Eigen::Vector2d& uv);

}  // namespace litgs::host::refine
