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
  const Eigen::Vector3d q = pose.q_world_cam.conjugate() * (x - pose.p_world_cam);
  if (q.z() <= 0.3 || q.norm() > max_range_m) return std::nullopt;
  const Eigen::Vector2d uv(c.fx * q.x() / q.z() + c.cx, c.fy * q.y() / q.z() + c.cy);
  if (uv.x() < 0 || uv.y() < 0 || uv.x() > c.width - 1 || uv.y() > c.height - 1) return std::nullopt;
  const double range = (x - pose.p_world_cam).norm();
  synth::Ray ray{pose.p_world_cam, (x - pose.p_world_cam) / range};
  const auto hit = world.cast(ray, 1e-3, range + 0.05);
  if (!hit || std::abs(hit->range_m - range) > 1e-3 + 1e-4 * range) return std::nullopt;
  return uv;
}

// Appends the observations of x in frames [first, last) to obs; with end_when_lost, stops where x is lost
// after it was seen (a feature track ends when it is lost). Returns the frame after the last one examined.
size_t observe(const synth::World& world, const std::vector<CameraPose>& truth, const PinholeCamera& c,
               const Eigen::Vector3d& x, size_t first, size_t last, const SyntheticTrackOptions& o,
               synth::Rng& rng, std::vector<Observation>& obs, bool end_when_lost) {
  size_t f = first;
  for (; f < last; ++f) {
    if (o.frozen_frames.count(f)) {
      // The frozen image repeats the previous one: the front end sees the previous frame's feature.
      if (!obs.empty() && obs.back().frame + 1 == f) obs.push_back({static_cast<uint32_t>(f), obs.back().uv});
      continue;
    }
    const auto uv = visible_at(world, truth[f], c, x, o.max_range_m);
    if (!uv) {
      if (end_when_lost && !obs.empty()) return f + 1;
      continue;
    }
    Observation ob;
    ob.frame = static_cast<uint32_t>(f);
    ob.uv = *uv + o.pixel_noise_px * Eigen::Vector2d(rng.normal(), rng.normal());
    if (rng.uniform() < o.outlier_fraction)
      ob.uv = {rng.uniform(0, c.width - 1), rng.uniform(0, c.height - 1)};
    obs.push_back(ob);
  }
  return f;
}

}  // namespace

std::vector<TrackPoint> synthetic_tracks(const synth::World& world, const std::vector<CameraPose>& truth,
                                         const std::vector<CameraPose>& estimate, const PinholeCamera& c,
                                         const std::vector<Eigen::Vector3d>& anchors_true,
                                         const SyntheticTrackOptions& o) {
  synth::Rng rng(o.seed);
  const size_t n = truth.size();
  std::vector<TrackPoint> out;
  auto add_track = [&](std::vector<Observation> obs) {
    if (obs.size() < 2) return;
    TrackPoint p;
    p.obs = std::move(obs);
    const auto X = triangulate(p.obs, estimate, c, o.triangulation);
    p.X = X ? *X : Eigen::Vector3d::Constant(std::numeric_limits<double>::quiet_NaN());
    p.active = X.has_value();
    out.push_back(std::move(p));
  };
  // The features' frames are drawn first, their observations after, so that the random draws of the
  // features do not depend on the anchors.
  struct Feature {
    Eigen::Vector3d x;
    size_t first, last;
  };
  std::vector<Feature> features;
  for (size_t f = 0; f < n; ++f)
    for (int k = 0; k < o.tracks_per_frame; ++k) {
      const Eigen::Vector3d d((rng.uniform(0, c.width) - c.cx) / c.fx,
                              (rng.uniform(0, c.height) - c.cy) / c.fy, 1);
      const auto hit =
          world.cast({truth[f].p_world_cam, (truth[f].q_world_cam * d).normalized()}, 0.3, o.max_range_m);
      const size_t length = static_cast<size_t>(rng.uniform_int(2, std::max(2, o.max_track_length)));
      if (hit) features.push_back({hit->point, f, std::min(n, f + length)});
    }
  for (const Feature& feature : features) {
    std::vector<Observation> obs;
    observe(world, truth, c, feature.x, feature.first, feature.last, o, rng, obs, true);
    add_track(std::move(obs));
  }
  for (const auto& a : anchors_true) {
    if (o.anchor_track_length <= 0) {  // one track through every frame that sees the anchor
      std::vector<Observation> obs;
      observe(world, truth, c, a, 0, n, o, rng, obs, /*end_when_lost=*/false);
      add_track(std::move(obs));
      continue;
    }
    for (size_t f = 0; f < n;) {  // sightings of a drawn length, each its own track
      const size_t length = static_cast<size_t>(rng.uniform_int(2, std::max(2, o.anchor_track_length)));
      size_t begin = f;  // the first frame that sees the anchor
      while (begin < n && !o.frozen_frames.count(begin) &&
             !visible_at(world, truth[begin], c, a, o.max_range_m))
        ++begin;
      if (begin >= n) break;
      std::vector<Observation> obs;
      f = observe(world, truth, c, a, begin, std::min(n, begin + length), o, rng, obs, true);
      add_track(std::move(obs));
    }
  }
  return out;
}

}  // namespace litgs::host::refine
