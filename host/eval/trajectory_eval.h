// The trajectories of a scene against its ground truth (gt/poses.txt), or, without one, against each other
// where refine ran (how far it moved each frame): ATE of the prior poses
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
  std::string frame = "camera";  // which moving frame the poses describe: "camera" or "imu" (poses_frame)
  bool has_truth = true;         // false: no gt/poses.txt, only the prior and the refined poses (no ATE)
  // Where refine ran: how far it moved the frames' positions (prior to refined), metres; -1 otherwise.
  double moved_mean_m = -1, moved_max_m = -1;
  // Top view: positions (truth, and the others after their alignment) in the plane of the truth's two
  // largest principal axes, about its centroid; metres. Without truth: the prior and refined positions as
  // they are, in the plane of the prior's axes.
  std::vector<Eigen::Vector2d> truth_top, prior_top, estimate_top;
  // Side view: the same positions in the plane of that first principal axis and the direction normal to the
  // top view's plane (for a ground survey, along the path and up), where height errors show.
  std::vector<Eigen::Vector2d> truth_side, prior_side, estimate_side;
};

// nullopt when the scene has neither gt/poses.txt nor poses_prior.txt (with the reason in *why_not).
// std::invalid_argument when fewer than 3 frames fall within both trajectories; io::IoError on unreadable
// files. `trained_on_truth`: the model was trained on gt/poses.txt (train --true-poses), so that is the
// estimate scored (an experiment's control row, whose ATE is then measured like the others').
std::optional<TrajectoryEvaluation> evaluate_trajectories(const std::filesystem::path& scene_dir,
                                                          std::string* why_not = nullptr,
                                                          bool trained_on_truth = false);

// to_json of evaluate_trajectories, or the string "not available: <why>" where the scene has no trajectory to
// score or too few frames within it (what eval writes; io::IoError still propagates).
nlohmann::json trajectory_json_or_reason(const std::filesystem::path& scene_dir,
                                         bool trained_on_truth = false);

// {"ate_m" (null without truth), "ate_prior_m" (or null), "moved_mean_m", "moved_max_m" (or null), "pairs",
// "alignment": "SE(3) Umeyama", "top_view" and "side_view": {"truth", "prior", "estimate"}: [[x, y], ...]}.
nlohmann::json to_json(const TrajectoryEvaluation& t);

}  // namespace litgs::host
