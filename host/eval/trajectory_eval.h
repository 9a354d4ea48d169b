// The trajectories of a scene against its ground truth (gt/poses.txt): ATE of the prior poses
// (poses_prior.txt, kept by refine) and of the current ones (poses.txt, refined where refine ran), each by
// host/refine's SE(3) Umeyama ATE, and a top view of the three for the report. Every trajectory is taken at
// the thermal frames' times (positions interpolated linearly; translation-only truth works the same way), in
// the frame poses.txt holds (camera or IMU, scene.yaml's poses_frame).
#pragma once

#include <Eigen/Core>
#include <filesystem>
#include <nlohmann/json.hpp>
#include <optional>
#include <string>
#include <vector>

#include "host/refine/ate.h"

namespace litgs::host {

struct TrajectoryEvaluation {
  std::optional<refine::AteResult>
      prior;                   // poses_prior.txt: before refinement (absent if refine did not run)
  refine::AteResult estimate;  // poses.txt (gt/poses.txt when the model was trained on it)
  bool trained_on_truth = false;
  // Top view: positions (truth, and the others after their alignment) in the plane of the truth's two
  // largest principal axes, about its centroid; metres.
  std::vector<Eigen::Vector2d> truth_top, prior_top, estimate_top;
};

// nullopt when the scene has no gt/poses.txt (with the reason in *why_not). std::invalid_argument when
// fewer than 3 frames fall within both trajectories; io::IoError on unreadable files. `trained_on_truth`:
// the model was trained on gt/poses.txt (train --true-poses), so that is the estimate scored (an experiment's
// control row, whose ATE is then measured like the others').
std::optional<TrajectoryEvaluation> evaluate_trajectories(const std::filesystem::path& scene_dir,
                                                          std::string* why_not = nullptr,
                                                          bool trained_on_truth = false);

// {"ate_m", "ate_prior_m" (or null), "pairs", "alignment": "SE(3) Umeyama", "top_view": {"truth", "prior",
// "estimate"}: [[x, y], ...]}.
nlohmann::json to_json(const TrajectoryEvaluation& t);

}  // namespace litgs::host
