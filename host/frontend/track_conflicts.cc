#include "host/frontend/track_conflicts.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <stdexcept>

namespace litgs::host::frontend {
namespace {

// Squared pixel reprojection error of X in `v`; infinity when X is not in front of the camera.
double error2_px(const TriangulationView& v, const Eigen::Vector3d& X, double fx, double fy) {
  const Eigen::Vector3d c = v.R_cam_world * X + v.t_cam_world;
  if (!(c.z() > 1e-6)) return std::numeric_limits<double>::infinity();
  const double ex = fx * (c.x() / c.z() - v.xy.x()), ey = fy * (c.y() / c.z() - v.xy.y());
  return ex * ex + ey * ey;
}

struct Support {
  std::vector<size_t> members;  // one observation index per agreeing image
  double error2_sum = 0;
};

// Per image, the remaining observation nearest X if within the bound.
Support support_of(const Eigen::Vector3d& X, const std::vector<size_t>& remaining,
                   const io::SfmTrack& component, const std::vector<std::optional<TriangulationView>>& views,
                   double fx, double fy, double bound2) {
  Support s;
  size_t k = 0;
  while (k < remaining.size()) {
    const uint32_t image = component.observations[remaining[k]].image;
    size_t best = SIZE_MAX;
    double best_e2 = bound2;
    for (; k < remaining.size() && component.observations[remaining[k]].image == image; ++k) {
      const auto& v = views[remaining[k]];
      if (!v) continue;
      const double e2 = error2_px(*v, X, fx, fy);
      if (e2 < best_e2) {
        best_e2 = e2;
        best = remaining[k];
      }
    }
    if (best != SIZE_MAX) {
      s.members.push_back(best);
      s.error2_sum += best_e2;
    }
  }
  return s;
}

}  // namespace

void ConflictOptions::check() const {
  if (!(max_error_px > 0)) throw std::invalid_argument("conflicts.max_error_px must be > 0");
  if (max_hypotheses < 1) throw std::invalid_argument("conflicts.max_hypotheses must be >= 1");
}

ConflictSplit split_conflicting_component(const io::SfmTrack& component,
                                          const std::vector<std::array<size_t, 2>>& edges,
                                          const ObservationView& view, double fx, double fy,
                                          const ConflictOptions& o) {
  o.check();
  const size_t n = component.observations.size();
  std::vector<std::optional<TriangulationView>> views(n);
  for (size_t i = 0; i < n; ++i) views[i] = view(component.observations[i]);
  std::vector<char> used(n, 0);
  std::vector<std::array<size_t, 2>> open = edges;
  ConflictSplit out;
  const double bound2 = o.max_error_px * o.max_error_px;
  while (true) {
    std::vector<size_t> remaining;
    for (size_t i = 0; i < n; ++i)
      if (!used[i]) remaining.push_back(i);
    std::erase_if(open, [&](const auto& e) {
      return e[0] >= n || e[1] >= n || used[e[0]] || used[e[1]] || !views[e[0]] || !views[e[1]];
    });
    if (open.empty()) break;
    const size_t step = std::max<size_t>(1, open.size() / o.max_hypotheses);
    Support best;
    for (size_t h = 0; h < open.size(); h += step) {
      const Eigen::Vector3d X = triangulate_linear({*views[open[h][0]], *views[open[h][1]]}, {0, 1});
      if (!X.allFinite()) continue;
      Support s = support_of(X, remaining, component, views, fx, fy, bound2);
      // Both ends of the hypothesis must agree with their own point (not behind a camera).
      if (std::find(s.members.begin(), s.members.end(), open[h][0]) == s.members.end() ||
          std::find(s.members.begin(), s.members.end(), open[h][1]) == s.members.end())
        continue;
      if (s.members.size() > best.members.size() ||
          (s.members.size() == best.members.size() && s.error2_sum < best.error2_sum))
        best = std::move(s);
    }
    if (best.members.size() < 2) break;
    io::SfmTrack t;
    for (size_t m : best.members) {
      used[m] = 1;
      t.observations.push_back(component.observations[m]);
    }
    out.tracks.push_back(std::move(t));
  }
  for (size_t i = 0; i < n; ++i) out.dropped += !used[i];
  return out;
}

}  // namespace litgs::host::frontend
