#include "host/refine/triangulation.h"

#include <Eigen/Dense>
#include <algorithm>
#include <cmath>

#include "host/refine/bundle_adjustment.h"

namespace litgs::host::refine {
namespace {

Eigen::Vector3d ray(const Observation& ob, const CameraPose& pose, const PinholeCamera& c) {
  return (pose.q_world_cam * Eigen::Vector3d((ob.uv.x() - c.cx) / c.fx, (ob.uv.y() - c.cy) / c.fy, 1.0))
      .normalized();
}

// Least-squares point nearest to every ray: sum (I - d d^T)(X - c) = 0.
std::optional<Eigen::Vector3d> midpoint(const std::vector<const Observation*>& obs,
                                        const std::vector<CameraPose>& poses, const PinholeCamera& c) {
  Eigen::Matrix3d A = Eigen::Matrix3d::Zero();
  Eigen::Vector3d b = Eigen::Vector3d::Zero();
  for (const Observation* ob : obs) {
    const Eigen::Vector3d d = ray(*ob, poses[ob->frame], c);
    const Eigen::Matrix3d P = Eigen::Matrix3d::Identity() - d * d.transpose();
    A += P;
    b += P * poses[ob->frame].p_world_cam;
  }
  const Eigen::LDLT<Eigen::Matrix3d> ldlt(A);
  if (ldlt.info() != Eigen::Success) return std::nullopt;
  const Eigen::Vector3d X = ldlt.solve(b);
  if (!X.allFinite()) return std::nullopt;
  return X;
}

// Parallax: the widest angle between the viewing rays in the world (zero under pure rotation, whatever
// the ill-conditioned midpoint came out as).
double widest_angle_deg(const std::vector<const Observation*>& obs, const std::vector<CameraPose>& poses,
                        const PinholeCamera& c) {
  double widest = 0;
  for (size_t i = 0; i < obs.size(); ++i)
    for (size_t j = i + 1; j < obs.size(); ++j) {
      const double cosine = ray(*obs[i], poses[obs[i]->frame], c).dot(ray(*obs[j], poses[obs[j]->frame], c));
      widest = std::max(widest, std::acos(std::clamp(cosine, -1.0, 1.0)));
    }
  return widest * 180 / M_PI;
}

}  // namespace

std::optional<Eigen::Vector3d> triangulate(const std::vector<Observation>& all,
                                           const std::vector<CameraPose>& poses, const PinholeCamera& c,
                                           const TriangulationOptions& o) {
  std::vector<const Observation*> obs;
  for (const auto& ob : all)
    if (ob.active && ob.frame < poses.size()) obs.push_back(&ob);
  if (obs.size() < 2) return std::nullopt;
  std::vector<const Observation*> best;
  // Pairs spread over the track (first with last, then inwards): the widest baselines first.
  std::vector<std::pair<size_t, size_t>> pairs;
  for (size_t gap = obs.size() - 1; gap >= 1 && pairs.size() < o.max_pair_trials; --gap)
    for (size_t i = 0; i + gap < obs.size() && pairs.size() < o.max_pair_trials; ++i)
      pairs.emplace_back(i, i + gap);
  for (const auto& [i, j] : pairs) {
    const auto X = midpoint({obs[i], obs[j]}, poses, c);
    if (!X) continue;
    std::vector<const Observation*> inliers;
    for (const Observation* ob : obs)
      if (reprojection_error_px(poses[ob->frame], c, *X, ob->uv) <= o.inlier_px) inliers.push_back(ob);
    if (inliers.size() > best.size()) best = inliers;
  }
  if (best.size() < 2) return std::nullopt;
  const auto X = midpoint(best, poses, c);
  if (!X) return std::nullopt;
  for (const Observation* ob : best)
    if (!(reprojection_error_px(poses[ob->frame], c, *X, ob->uv) < 1e6)) return std::nullopt;  // behind
  if (widest_angle_deg(best, poses, c) < o.min_angle_deg) return std::nullopt;
  return X;
}

}  // namespace litgs::host::refine
