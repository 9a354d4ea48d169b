#include "host/refine/synthetic_tracks.h"

#include <cmath>
#include <limits>

#include "host/synth/rng.h"

namespace litgs::host::refine {
namespace {

// The pixel of x in `pose` if the world shows x there (nothing nearer along the ray).
std::optional<Eigen::Vector2d> visible_at(const synth::World& world, const CameraPose& pose,
                                          const PinholeCamera& c, const Eigen::Vector3d& x,
                                          double max_range_m) {
  const Eigen::Vector3d q = pose.q.conjugate() * (x - pose.p);
  if (q.z() <= 0.3 || q.norm() > max_range_m) return std::nullopt;
  const Eigen::Vector2d uv(c.fx * q.x() / q.z() + c.cx, c.fy * q.y() / q.z() + c.cy);
  if (uv.x() < 0 || uv.y() < 0 || uv.x() > c.width - 1 || uv.y() > c.height - 1) return std::nullopt;
  const double range = (x - pose.p).norm();
  synth::Ray ray{pose.p, (x - pose.p) / range};
  const auto hit = world.cast(ray, 1e-3, range + 0.05);
  if (!hit || std::abs(hit->range_m - range) > 1e-3 + 1e-4 * range) return std::nullopt;
  return uv;
}

}  // namespace

std::vector<TrackPoint> synthetic_tracks(const synth::World& world, const std::vector<CameraPose>& truth,
                                         const std::vector<CameraPose>& estimate, const PinholeCamera& c,
                                         const std::vector<Eigen::Vector3d>& anchors_true,
                                         const SyntheticTrackOptions& o) {
  synth::Rng rng(o.seed);
  std::vector<std::pair<Eigen::Vector3d, std::pair<size_t, size_t>>> sources;  // point, frame range
  const size_t n = truth.size();
  for (size_t f = 0; f < n; ++f)
    for (int k = 0; k < o.tracks_per_frame; ++k) {
      const Eigen::Vector3d d((rng.uniform(0, c.width) - c.cx) / c.fx,
                              (rng.uniform(0, c.height) - c.cy) / c.fy, 1);
      const auto hit = world.cast({truth[f].p, (truth[f].q * d).normalized()}, 0.3, o.max_range_m);
      const int length = rng.uniform_int(2, std::max(2, o.max_track_length));
      if (hit) sources.push_back({hit->point, {f, std::min(n, f + static_cast<size_t>(length))}});
    }
  for (const auto& a : anchors_true) sources.push_back({a, {0, n}});
  std::vector<TrackPoint> out;
  for (const auto& [x, range] : sources) {
    TrackPoint p;
    bool started = false;
    for (size_t f = range.first; f < range.second; ++f) {
      if (o.frozen_frames.count(f)) {
        // The frozen image repeats the previous one: the front end sees the previous frame's feature.
        if (!p.obs.empty() && p.obs.back().frame + 1 == f)
          p.obs.push_back({static_cast<uint32_t>(f), p.obs.back().uv});
        continue;
      }
      const auto uv = visible_at(world, truth[f], c, x, o.max_range_m);
      if (!uv) {
        if (started && range.second - range.first < n) break;  // a feature track ends when it is lost
        continue;
      }
      started = true;
      Observation ob;
      ob.frame = static_cast<uint32_t>(f);
      ob.uv = *uv + o.pixel_noise_px * Eigen::Vector2d(rng.normal(), rng.normal());
      if (rng.uniform() < o.outlier_fraction)
        ob.uv = {rng.uniform(0, c.width - 1), rng.uniform(0, c.height - 1)};
      p.obs.push_back(ob);
    }
    if (p.obs.size() < 2) continue;
    const auto X = triangulate(p.obs, estimate, c, o.triangulation);
    p.X = X ? *X : Eigen::Vector3d::Constant(std::numeric_limits<double>::quiet_NaN());
    p.active = X.has_value();
    out.push_back(std::move(p));
  }
  return out;
}

}  // namespace litgs::host::refine
