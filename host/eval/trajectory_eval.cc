#include "host/eval/trajectory_eval.h"

#include <Eigen/Eigenvalues>
#include <algorithm>
#include <stdexcept>

#include "io/scene.h"
#include "io/tum.h"

namespace litgs::host {
namespace {

namespace fs = std::filesystem;

// Position at time t, linear between the poses around it; nullopt outside the trajectory.
std::optional<Eigen::Vector3d> position_at(const std::vector<io::TumPose>& poses, double t) {
  const auto after = std::lower_bound(poses.begin(), poses.end(), t,
                                      [](const io::TumPose& p, double time) { return p.t_s < time; });
  if (after == poses.end()) return std::nullopt;
  if (after->t_s == t) return after->p_world;
  if (after == poses.begin()) return std::nullopt;
  const io::TumPose& before = *(after - 1);
  const double w = (t - before.t_s) / (after->t_s - before.t_s);
  return ((1 - w) * before.p_world + w * after->p_world).eval();
}

// The trajectory at the given times (positions only: ATE uses nothing else).
std::vector<io::TumPose> at_times(const std::vector<io::TumPose>& poses, const std::vector<double>& times) {
  std::vector<io::TumPose> out;
  for (double t : times)
    if (const auto p = position_at(poses, t)) {
      io::TumPose pose;  // the rotation stays identity: unused
      pose.t_s = t;
      pose.p_world = *p;
      out.push_back(pose);
    }
  return out;
}

// Positions (after `align`) in the plane of `axes` about `centre`.
std::vector<Eigen::Vector2d> in_plane(const std::vector<io::TumPose>& poses, const refine::Similarity& align,
                                      const Eigen::Vector3d& centre,
                                      const Eigen::Matrix<double, 3, 2>& axes) {
  std::vector<Eigen::Vector2d> out;
  for (const auto& p : poses) out.push_back(axes.transpose() * (align.apply(p.p_world) - centre));
  return out;
}

// The plane of the positions' two largest principal axes, about their centroid.
void principal_plane(const std::vector<io::TumPose>& poses, Eigen::Vector3d& centre,
                     Eigen::Matrix<double, 3, 2>& axes) {
  centre = Eigen::Vector3d::Zero();
  for (const auto& p : poses) centre += p.p_world / static_cast<double>(poses.size());
  Eigen::Matrix3d scatter = Eigen::Matrix3d::Zero();
  for (const auto& p : poses) scatter += (p.p_world - centre) * (p.p_world - centre).transpose();
  const Eigen::SelfAdjointEigenSolver<Eigen::Matrix3d> eig(scatter);  // eigenvalues ascending
  axes.col(0) = eig.eigenvectors().col(2);
  axes.col(1) = eig.eigenvectors().col(1);
}

// The positions' principal axes about their centroid, largest first: the top view is the plane of the first
// two, the side view that of the first and the last (for a ground or facade survey, along the path and up).
struct ViewPlanes {
  Eigen::Vector3d centre;
  Eigen::Matrix<double, 3, 2> top, side;
};
ViewPlanes principal_planes(const std::vector<io::TumPose>& poses) {
  ViewPlanes v;
  Eigen::Matrix<double, 3, 2> axes;
  principal_plane(poses, v.centre, axes);
  v.top = axes;
  v.side.col(0) = axes.col(0);
  v.side.col(1) = axes.col(0).cross(axes.col(1)).normalized();
  if (v.side.col(1).z() < 0) v.side.col(1) = -v.side.col(1);  // up, where the world's z is up
  return v;
}

// How far refinement moved each frame (both trajectories at the same times, in one frame).
void moved(const std::vector<io::TumPose>& prior, const std::vector<io::TumPose>& refined,
           TrajectoryEvaluation& r) {
  const size_t n = std::min(prior.size(), refined.size());
  if (n == 0) return;
  double sum = 0, most = 0;
  for (size_t i = 0; i < n; ++i) {
    const double d = (refined[i].p_world - prior[i].p_world).norm();
    sum += d;
    most = std::max(most, d);
  }
  r.moved_mean_m = sum / static_cast<double>(n);
  r.moved_max_m = most;
}

// No ground truth: the prior and refined trajectories as they are, for the report's top view.
TrajectoryEvaluation without_truth(const std::vector<io::TumPose>& prior,
                                   const std::vector<io::TumPose>& refined) {
  if (prior.size() != refined.size())
    throw std::invalid_argument("poses_prior.txt and poses.txt do not cover the same frames (" +
                                std::to_string(prior.size()) + " and " + std::to_string(refined.size()) +
                                ")");
  if (prior.size() < 3)
    throw std::invalid_argument("poses_prior.txt covers " + std::to_string(prior.size()) +
                                " frames, fewer than 3");
  TrajectoryEvaluation r;
  r.has_truth = false;
  r.estimate.pairs = refined.size();
  const ViewPlanes v = principal_planes(prior);
  r.prior_top = in_plane(prior, {}, v.centre, v.top);
  r.estimate_top = in_plane(refined, {}, v.centre, v.top);
  r.prior_side = in_plane(prior, {}, v.centre, v.side);
  r.estimate_side = in_plane(refined, {}, v.centre, v.side);
  moved(prior, refined, r);
  return r;
}

std::string frame_name(io::PoseFrame f) {
  return f == io::PoseFrame::kImu ? "imu" : "camera";
}

}  // namespace

std::optional<TrajectoryEvaluation> evaluate_trajectories(const fs::path& dir, std::string* why_not,
                                                          bool trained_on_truth) {
  io::SceneReadOptions ro;
  ro.check_images = false;
  ro.load_map = false;
  const io::Scene scene = io::read_scene(dir, ro);
  std::vector<double> times;
  for (const auto& f : scene.frames) times.push_back(f.t_s);
  if (!scene.gt || scene.gt->poses.size() < 3) {
    if (!fs::exists(dir / "poses_prior.txt") || trained_on_truth) {
      if (why_not) *why_not = "the scene has no gt/poses.txt (ground truth), and refine did not run";
      return std::nullopt;
    }
    TrajectoryEvaluation r =
        without_truth(at_times(io::read_tum(dir / "poses_prior.txt"), times), at_times(scene.poses, times));
    r.frame = frame_name(scene.config.poses_frame);
    return r;
  }
  const std::vector<io::TumPose> truth = at_times(scene.gt->poses, times);
  constexpr double kSameTime = 1e-9;  // all three are sampled at the same frame times
  TrajectoryEvaluation r;
  r.trained_on_truth = trained_on_truth;
  r.frame = frame_name(scene.config.poses_frame);
  const std::vector<io::TumPose> estimate = at_times(trained_on_truth ? scene.gt->poses : scene.poses, times);
  r.estimate = refine::absolute_trajectory_error(estimate, truth, refine::AteAlignment::kSE3, kSameTime);
  std::vector<io::TumPose> prior;
  if (fs::exists(dir / "poses_prior.txt")) {
    prior = at_times(io::read_tum(dir / "poses_prior.txt"), times);
    r.prior = refine::absolute_trajectory_error(prior, truth, refine::AteAlignment::kSE3, kSameTime);
  }
  // The top view: the plane of the truth's two largest principal axes (for a ground or facade survey, the
  // horizontal plane).
  const ViewPlanes v = principal_planes(truth);
  r.truth_top = in_plane(truth, {}, v.centre, v.top);
  r.estimate_top = in_plane(estimate, r.estimate.alignment, v.centre, v.top);
  r.truth_side = in_plane(truth, {}, v.centre, v.side);
  r.estimate_side = in_plane(estimate, r.estimate.alignment, v.centre, v.side);
  if (r.prior) {
    r.prior_top = in_plane(prior, r.prior->alignment, v.centre, v.top);
    r.prior_side = in_plane(prior, r.prior->alignment, v.centre, v.side);
    if (!trained_on_truth) moved(prior, estimate, r);
  }
  return r;
}

nlohmann::json to_json(const TrajectoryEvaluation& t) {
  const auto points = [](const std::vector<Eigen::Vector2d>& v) {
    nlohmann::json a = nlohmann::json::array();
    for (const auto& p : v) a.push_back({p.x(), p.y()});
    return a;
  };
  const auto or_null = [](bool known, double v) {
    return known ? nlohmann::json(v) : nlohmann::json(nullptr);
  };
  return {{"ate_m", or_null(t.has_truth, t.estimate.rmse_m)},
          {"ate_prior_m", or_null(t.has_truth && t.prior.has_value(), t.prior ? t.prior->rmse_m : 0.0)},
          {"moved_mean_m", or_null(t.moved_mean_m >= 0, t.moved_mean_m)},
          {"moved_max_m", or_null(t.moved_max_m >= 0, t.moved_max_m)},
          {"pairs", t.estimate.pairs},
          {"frame", t.frame},
          {"poses", t.trained_on_truth ? "gt/poses.txt (the model was trained on the truth)" : "poses.txt"},
          {"alignment", t.has_truth ? "SE(3) Umeyama, positions at the frame times"
                                    : "none: no ground truth; the prior and refined positions as they are"},
          {"top_view",
           {{"truth", points(t.truth_top)},
            {"prior", points(t.prior_top)},
            {"estimate", points(t.estimate_top)}}},
          {"side_view",
           {{"truth", points(t.truth_side)},
            {"prior", points(t.prior_side)},
            {"estimate", points(t.estimate_side)}}}};
}

nlohmann::json trajectory_json_or_reason(const std::filesystem::path& scene_dir, bool trained_on_truth) {
  std::string why_not;
  try {
    if (const auto t = evaluate_trajectories(scene_dir, &why_not, trained_on_truth)) return to_json(*t);
  } catch (const std::invalid_argument& error) {
    why_not = error.what();
  }
  return "not available: " + why_not;
}

}  // namespace litgs::host
