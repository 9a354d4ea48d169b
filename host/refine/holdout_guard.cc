#include "host/refine/holdout_guard.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <optional>
#include <stdexcept>

#include "host/refine/bundle_adjustment.h"
#include "host/refine/triangulate_track.h"
#include "io/robust_stats.h"

namespace litgs::host::refine {
namespace {

// Gauss-Newton on the pixel error of `obs` through `poses`, from X: the point that fits its poses best, so
// that what remains is the poses' disagreement.
std::optional<Eigen::Vector3d> fit_point(const std::vector<Observation>& obs,
                                         const std::vector<CameraPose>& poses, const PinholeCamera& camera,
                                         Eigen::Vector3d X) {
  for (int it = 0; it < 5; ++it) {
    Eigen::Matrix3d H = Eigen::Matrix3d::Zero();
    Eigen::Vector3d g = Eigen::Vector3d::Zero();
    for (const auto& o : obs) {
      const CameraPose& c = poses[o.frame];
      const Eigen::Vector3d pc = c.q_world_cam.conjugate() * (X - c.p_world_cam);
      if (!(pc.z() > 1e-6)) continue;
      const Eigen::Vector2d r(camera.fx * pc.x() / pc.z() + camera.cx - o.uv.x(),
                              camera.fy * pc.y() / pc.z() + camera.cy - o.uv.y());
      Eigen::Matrix<double, 2, 3> J_pc;
      J_pc << camera.fx / pc.z(), 0, -camera.fx * pc.x() / (pc.z() * pc.z()), 0, camera.fy / pc.z(),
          -camera.fy * pc.y() / (pc.z() * pc.z());
      const Eigen::Matrix<double, 2, 3> J = J_pc * c.q_world_cam.conjugate().toRotationMatrix();
      H += J.transpose() * J;
      g += J.transpose() * r;
    }
    const Eigen::Vector3d step = H.ldlt().solve(-g);
    if (!step.allFinite()) break;
    X += step;
    if (step.norm() < 1e-9) break;
  }
  if (!X.allFinite()) return std::nullopt;
  return X;
}

}  // namespace

void HoldoutOptions::check() const {
  if (every == 1) throw std::invalid_argument("refine: holdout every must be 0 (off) or >= 2");
  if (!(tolerance >= 0)) throw std::invalid_argument("refine: holdout tolerance must be >= 0");
}

std::vector<TrackPoint> hold_out_tracks(std::vector<TrackPoint>& points, const HoldoutOptions& o) {
  o.check();
  std::vector<TrackPoint> held, kept;
  if (o.every == 0) return held;
  for (size_t i = 0; i < points.size(); ++i) (i % o.every == o.every - 1 ? held : kept).push_back(points[i]);
  points = std::move(kept);
  return held;
}

HoldoutVerdict judge_on_held_out(const std::vector<TrackPoint>& held_out,
                                 const std::vector<CameraPose>& priors,
                                 const std::vector<CameraPose>& refined, const PinholeCamera& camera,
                                 const HoldoutOptions& o) {
  HoldoutVerdict v;
  v.tracks = held_out.size();
  std::vector<double> e_prior, e_refined;
  for (const auto& t : held_out) {
    std::vector<Observation> obs;
    for (const auto& ob : t.obs)
      if (ob.frame < priors.size() && ob.frame < refined.size()) obs.push_back(ob);
    if (obs.size() < 2) continue;
    // The track's consensus point through each pose set; the observations that agree with either (wrong
    // matches agree with neither) are fitted and scored through both, so that the medians compare.
    const auto Xp0 = triangulate(obs, priors, camera), Xr0 = triangulate(obs, refined, camera);
    if (!Xp0 || !Xr0) continue;
    std::vector<Observation> agreeing;
    for (const auto& ob : obs)
      if (reprojection_error_px(priors[ob.frame], camera, *Xp0, ob.uv) <= o.agree_px ||
          reprojection_error_px(refined[ob.frame], camera, *Xr0, ob.uv) <= o.agree_px)
        agreeing.push_back(ob);
    if (agreeing.size() < 2) continue;
    const auto Xp = fit_point(agreeing, priors, camera, *Xp0),
               Xr = fit_point(agreeing, refined, camera, *Xr0);
    if (!Xp || !Xr) continue;
    for (const auto& ob : agreeing) {
      const double ep = reprojection_error_px(priors[ob.frame], camera, *Xp, ob.uv);
      const double er = reprojection_error_px(refined[ob.frame], camera, *Xr, ob.uv);
      if (!std::isfinite(ep) || !std::isfinite(er)) continue;
      e_prior.push_back(ep);
      e_refined.push_back(er);
    }
    ++v.tracks_used;
  }
  v.observations = e_prior.size();
  v.prior_median_px = io::median(e_prior);
  v.refined_median_px = io::median(e_refined);
  v.measured = v.tracks_used >= o.min_tracks;
  v.keep_refined = !v.measured || v.refined_median_px <= (1 + o.tolerance) * v.prior_median_px;
  char text[320];
  if (!v.measured)
    std::snprintf(text, sizeof text,
                  "held-back tracks: %zu of %zu could be triangulated both ways (%zu needed): no verdict",
                  v.tracks_used, v.tracks, o.min_tracks);
  else
    std::snprintf(text, sizeof text,
                  "held-back tracks (%zu, %zu observations): median reprojection %.3f px through the priors, "
                  "%.3f px through the refined poses: %s",
                  v.tracks_used, v.observations, v.prior_median_px, v.refined_median_px,
                  v.keep_refined ? "refined poses kept" : "worse, the priors are kept");
  v.summary = text;
  return v;
}

}  // namespace litgs::host::refine
