// The refinement: associations, weights and Ceres solves in rounds (docs/refinement.md). Round 0 runs
// sliding windows (local) before its global solve; every round re-associates points with LiDAR planes (a
// shrinking radius) and recomputes the weights; between rounds, residuals above median + k * 1.4826 * MAD
// (with a floor) are rejected and counted. No Ceres or PCL here.
#pragma once

#include <string>
#include <vector>

#include "host/refine/association.h"
#include "host/refine/bundle_adjustment.h"
#include "host/refine/holdout_guard.h"
#include "host/refine/scan_alignment.h"
#include "host/refine/weights.h"

namespace litgs::host::refine {

struct RefineOptions {
  // Rounds of association, solve and rejection. 8: on the front end's own tracks (more wrong matches than
  // the oracle's) the rejection between rounds keeps paying after round 5 (docs/experiments.md, "the
  // refinement on the engine's own tracks", issue 44); with oracle tracks 5 were enough.
  size_t rounds = 8;
  bool use_anchors = true, use_planes = true;
  size_t window = 20;             // frames per local window (step: half of it); 0: no local pass
  double reject_k = 3;            // rejection bound: median + k * 1.4826 * MAD ...
  double reject_floor_px = 1.5;   // ... but never below this (reprojection, pixels)
  double reject_floor_m = 0.03;   // ... or this (point-to-plane, metres)
  size_t anchors_from_round = 1;  // 0-based: the first round is solved without anchors (docs/refinement.md)
  int threads = 1;
  int max_iterations = 50;  // per Ceres solve
  // Observability: a frame with fewer active observations than this is weakly constrained by the images
  // (COLMAP registers an image only with 30 inliers). When more than half of the frames are, the tracks
  // cannot refine the poses (a few noisy points per frame move them the wrong way): refine stops before
  // solving and keeps the priors. 0: off.
  size_t min_frame_observations = 30;
  // Tracks held back from the solve to judge it (holdout_guard.h): refined poses that explain them worse
  // than the priors are not kept.
  HoldoutOptions holdout;
  WeightOptions weights;
  AnchorAssociationOptions anchor_association;
  PlaneAssociationOptions plane_association;
  // The LiDAR scans in the solve (scan_alignment.h), when the input has them, from
  // scan_alignment.from_round on (docs/refinement.md, "Scans in the solve").
  bool use_scans = true;
  ScanAlignmentOptions scan_alignment;
  BaWeights ba;
  void check() const;  // std::invalid_argument naming the bad field
};

struct RefineInput {
  PinholeCamera camera;
  std::vector<CameraPose> priors;  // the odometry, one per frame, by time
  std::vector<TrackPoint> points;  // observations undistorted; X the initial triangulation
  std::vector<AnchorPoint> anchors;
  const PlanarMap* map = nullptr;  // the LiDAR map's plane fits; null: none
  std::vector<RefineScan> scans;   // the scans tied to their frames (not the guard's held-out ones)
};

struct ResidualStats {
  size_t observations = 0;  // active
  // Active observations whose point lies behind (or on) their camera: no finite reprojection error; the
  // RMS and median are over the others.
  size_t behind_camera = 0;
  double reprojection_rms_px = 0, reprojection_median_px = 0;
  // The observations of anchored points alone (TrackPoint::anchor set): an anchor prior that disagrees with
  // the tracks shows here first.
  size_t anchored_observations = 0;
  double anchored_reprojection_rms_px = 0;
  size_t plane_points = 0;
  double plane_rms_m = 0;
};

struct RoundReport {
  bool local = false;  // sliding windows ran before the global solve
  size_t local_solves = 0;
  ResidualStats before, after;
  PlaneAssociationReport planes;
  ScanAssociationReport scans;
  double scan_rms_before_m = 0, scan_rms_after_m = 0;  // the scan links' point-to-plane RMS
  size_t rejected_observations = 0, rejected_planes = 0, dropped_points = 0;  // after this round
  double reject_bound_px = 0, reject_bound_m = 0;
  BaSolveSummary global;
  double seconds = 0;
};

struct RefineReport {
  std::string status = "converged";  // or the reason it stopped early, or why the priors were kept
  bool stopped_early = false;
  // "refined": the refined poses are the output; "kept the priors": the solve ran but the held-back tracks
  // judged it worse; "stopped": it stopped before or during the solve (the priors or the last good round).
  std::string outcome = "refined";
  HoldoutVerdict holdout;
  std::vector<CameraPose> rejected_poses;  // the solve's poses when a guard kept the priors instead
  size_t frames = 0, points = 0, observations = 0, anchors = 0;
  size_t frozen_frames = 0;          // frames whose observations repeat the previous frame's: dropped
  size_t untriangulated_points = 0;  // inactive from the start (non-finite or fewer than 2 observations)
  size_t weak_frames = 0;  // frames with fewer than min_frame_observations active observations at the start
  double median_frame_observations = 0;
  size_t fewest_frame_observations = 0;    // over the frames with any observation, at the start
  size_t frames_without_observations = 0;  // not detected as frozen here (e.g. skipped by the front end)
  AnchorAssociationReport anchor_association;
  size_t guarded_anchor_covariances = 0;
  double anchor_weight_median_raw = 0;  // m^-3
  std::vector<double> alphas;           // per frame
  ResidualStats before, after;
  std::vector<RoundReport> rounds;
  double seconds = 0;
  std::vector<std::string> notes;
};

// Refines `poses` (initialized by the caller, usually to the priors) and the points in place.
RefineReport refine(RefineInput& input, std::vector<CameraPose>& poses, const RefineOptions& options);

ResidualStats residual_stats(const std::vector<TrackPoint>& points, const std::vector<CameraPose>& poses,
                             const PinholeCamera& camera);

// Every pose and every active point finite.
bool all_finite(const std::vector<CameraPose>& poses, const std::vector<TrackPoint>& points);

}  // namespace litgs::host::refine
