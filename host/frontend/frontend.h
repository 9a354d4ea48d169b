// The thermal front end: frames and prior poses -> verified matches, tracks and triangulated points
// (`litgs-engine match`, docs/frontend.md). CPU, OpenCV inside the .cc files only.
#pragma once

#include <filesystem>
#include <functional>
#include <string>
#include <vector>

#include "host/frontend/features.h"
#include "host/frontend/lidar_depth_check.h"
#include "host/frontend/matching.h"
#include "host/frontend/pair_selection.h"
#include "host/frontend/preprocess.h"
#include "host/frontend/track_conflicts.h"
#include "host/frontend/triangulation.h"
#include "host/frontend/verification.h"
#include "io/sfm_files.h"

namespace litgs::host::frontend {

struct FrontendOptions {
  PreprocessOptions preprocess;
  FeatureOptions features;
  LearnedDetector learned_detector;  // required for FeatureType::kXfeat (host/nn/xfeat_features.h)
  MatchOptions match;
  LearnedMatcher learned_matcher;  // required for Matcher::kLighterGlue (host/nn/lighterglue_matcher.h)
  VerifyOptions verify;
  bool prior_epipolar = true;  // reject matches far from the prior poses' epipolar lines
  // Reject verified matches the LiDAR map contradicts (lidar_depth_check.h); not with true_poses, whose
  // frame the map (built through the odometry) is not in.
  LidarCheckOptions lidar_check;
  PairOptions pairs;
  TriangulationOptions triangulation;
  // Tracks that would hold two keypoints of one image are split by the prior poses (track_conflicts.h);
  // false: the later match is refused (images without a prior pose are never split).
  bool split_conflicts = true;
  ConflictOptions conflicts;
  int threads = 0;  // 0: all cores
  // Priors from gt/poses.txt instead of poses.txt (synthetic experiments that separate the front end from
  // the estimator's drift); an error if the scene has none.
  bool true_poses = false;
  void check() const;
};

struct PairStats {
  uint32_t image_a = 0, image_b = 0;
  size_t mutual = 0, verified = 0, rejected_by_prior = 0;
  size_t rejected_by_lidar = 0;  // essential-matrix inliers the LiDAR map contradicts (not in `verified`)
  bool accepted = false;         // at least min_inliers verified
};

struct StageSeconds {
  double preprocess = 0, features = 0, pair_selection = 0, matching = 0;
  double triangulation = 0;  // tracks and points
  double total = 0;
};

struct FrontendSummary {
  size_t images = 0, frozen = 0, uniform = 0, without_pose = 0;
  size_t keypoints = 0;
  double keypoints_per_image = 0;  // over the images matched (not frozen)
  size_t pairs_tried = 0, pairs_verified = 0;
  size_t mutual_matches = 0, verified_matches = 0, rejected_by_prior = 0, rejected_by_lidar = 0;
  size_t lidar_checked_images = 0;  // images with a LiDAR depth image (0: the check did not run)
  double inlier_ratio = 0;          // verified / mutual over all pairs tried (the sequence's)
  size_t tracks = 0, points = 0;
  // Verified matches lost to conflicts (their keypoints ended in different tracks, or in none), out of
  // track_matches; the components split and their keypoints kept in a track or dropped.
  size_t track_conflicts = 0, track_matches = 0;
  size_t conflicting_components = 0, conflict_keypoints_kept = 0, conflict_keypoints_dropped = 0;
  size_t rejected_no_angle = 0, rejected_depth = 0, rejected_error = 0, rejected_few_views = 0;
  double mean_track_length = 0, mean_error_px = 0;
  // Scenes with gt/planes.txt: each point's distance to the nearest true plane, median and mean (metres);
  // -1 without true planes or points.
  double true_plane_median_m = -1, true_plane_mean_m = -1;
  StageSeconds seconds;
  std::vector<std::string> notes;
};

struct FrontendResult {
  io::SfmData data;
  std::vector<PairStats> pairs;
  FrontendSummary summary;
  std::vector<std::string> frozen_frames;  // file names
  FrontendOptions options;
};

// stage ("features", "matching", ...), done, total; called from the calling thread.
using FrontendProgress = std::function<void(const std::string& stage, size_t done, size_t total)>;

// Runs every stage on the scene in `scene_dir`. IoError from the readers (a frame of the wrong size names
// the file); std::invalid_argument for bad options or a scene without frames. Empty results are results.
FrontendResult run_frontend(const std::filesystem::path& scene_dir, const FrontendOptions& options,
                            const FrontendProgress& progress = {});

// frontend.json's text: options, summary, per-pair statistics, frozen frames.
std::string frontend_json(const FrontendResult& result);

// Writes scene_dir/sfm/ (io::write_sfm): every file atomically, frontend.json last.
void write_frontend(const std::filesystem::path& scene_dir, const FrontendResult& result);

}  // namespace litgs::host::frontend
