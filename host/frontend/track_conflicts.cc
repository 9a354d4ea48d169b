#include "host/frontend/track_conflicts.h"

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <limits>
#include <map>
#include <stdexcept>

#include "host/frontend/observations_by_image.h"

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
  Eigen::Vector3d X = Eigen::Vector3d::Constant(NAN);  // the point they agree with
};

// Per image, the unused observation nearest X (the first in index order on a tie) if within the bound.
Support support_of(const Eigen::Vector3d& X, const std::vector<char>& used, const ObservationsByImage& index,
                   const std::vector<std::optional<TriangulationView>>& views, double fx, double fy,
                   double bound2) {
  Support s;
  s.X = X;
  for (size_t slot = 0; slot < index.slots(); ++slot) {
    size_t best = SIZE_MAX;
    double best_e2 = bound2;
    index.near(slot, X, [&](size_t i) {
      if (used[i]) return;
      const double e2 = error2_px(*views[i], X, fx, fy);
      if (e2 < best_e2 || (e2 == best_e2 && best != SIZE_MAX && i < best)) {
        best_e2 = e2;
        best = i;
      }
    });
    if (best != SIZE_MAX) {
      s.members.push_back(best);
      s.error2_sum += best_e2;
    }
  }
  return s;
}

// The linear point of the given observations (their views; every one posed); non-finite if degenerate.
Eigen::Vector3d point_of(const std::vector<size_t>& members,
                         const std::vector<std::optional<TriangulationView>>& views) {
  std::vector<TriangulationView> member_views;
  for (size_t m : members) member_views.push_back(*views[m]);
  std::vector<size_t> all(member_views.size());
  for (size_t k = 0; k < all.size(); ++k) all[k] = k;
  return triangulate_linear(member_views, all);
}

// Each observation's group (index into `groups`), SIZE_MAX for those in none.
std::vector<size_t> group_of_each(const std::vector<std::vector<size_t>>& groups, size_t observations) {
  std::vector<size_t> group_of(observations, SIZE_MAX);
  for (size_t g = 0; g < groups.size(); ++g)
    for (size_t m : groups[g]) group_of[m] = g;
  return group_of;
}

// Tracks of one point that the priors' drift split in time: two groups without a shared image, joined by
// verified matches, whose union still reprojects within merge_factor times the bound. Pairs with more
// matches between them merge first. Empties the groups merged away.
void merge_disjoint_groups(std::vector<std::vector<size_t>>& groups,
                           const std::vector<std::array<size_t, 2>>& edges, const io::SfmTrack& component,
                           const std::vector<std::optional<TriangulationView>>& views, double fx, double fy,
                           const ConflictOptions& o) {
  if (!(o.merge_factor > 0) || groups.size() < 2) return;
  const std::vector<size_t> group_of = group_of_each(groups, component.observations.size());
  std::map<std::pair<size_t, size_t>, size_t> links;
  for (const auto& e : edges) {
    if (e[0] >= group_of.size() || e[1] >= group_of.size()) continue;
    const size_t a = group_of[e[0]], b = group_of[e[1]];
    if (a != SIZE_MAX && b != SIZE_MAX && a != b) ++links[{std::min(a, b), std::max(a, b)}];
  }
  std::vector<std::pair<size_t, std::pair<size_t, size_t>>> order;
  for (const auto& [pair, count] : links) order.push_back({count, pair});
  std::stable_sort(order.begin(), order.end(),
                   [](const auto& x, const auto& y) { return x.first > y.first; });
  std::vector<size_t> root(groups.size());
  for (size_t g = 0; g < root.size(); ++g) root[g] = g;
  auto find = [&root](size_t g) {
    while (root[g] != g) g = root[g] = root[root[g]];
    return g;
  };
  const double bound = o.merge_factor * o.max_error_px;
  for (const auto& [count, pair] : order) {
    const size_t a = find(pair.first), b = find(pair.second);
    if (a == b) continue;
    std::vector<size_t> joined = groups[a];
    joined.insert(joined.end(), groups[b].begin(), groups[b].end());
    std::vector<uint32_t> images;
    for (size_t m : joined) images.push_back(component.observations[m].image);
    std::sort(images.begin(), images.end());
    if (std::adjacent_find(images.begin(), images.end()) != images.end()) continue;
    const Eigen::Vector3d X = point_of(joined, views);
    if (!X.allFinite()) continue;
    const bool consistent = std::all_of(joined.begin(), joined.end(), [&](size_t m) {
      return error2_px(*views[m], X, fx, fy) <= bound * bound;
    });
    if (!consistent) continue;
    groups[a] = std::move(joined);
    groups[b].clear();
    root[b] = a;
  }
}

// Observations no hypothesis took, because the priors' drift put them just beyond the bound: each joins a
// track it has verified matches with, that has no observation in its image, and whose point it sees within
// merge_factor times the bound.
void attach_dropped(std::vector<std::vector<size_t>>& groups, std::vector<char>& used,
                    const std::vector<std::array<size_t, 2>>& edges, const io::SfmTrack& component,
                    const std::vector<std::optional<TriangulationView>>& views, double fx, double fy,
                    const ConflictOptions& o) {
  if (!(o.merge_factor > 0) || groups.empty()) return;
  const size_t n = component.observations.size();
  const std::vector<size_t> group_of = group_of_each(groups, n);
  std::vector<std::map<size_t, size_t>> links(n);  // per dropped observation: group -> matches
  for (const auto& e : edges) {
    if (e[0] >= n || e[1] >= n) continue;
    if (!used[e[0]] && group_of[e[1]] != SIZE_MAX) ++links[e[0]][group_of[e[1]]];
    if (!used[e[1]] && group_of[e[0]] != SIZE_MAX) ++links[e[1]][group_of[e[0]]];
  }
  std::vector<std::optional<Eigen::Vector3d>> point(groups.size());
  const double bound2 = o.merge_factor * o.max_error_px * o.merge_factor * o.max_error_px;
  for (size_t i = 0; i < n; ++i) {
    if (used[i] || !views[i] || links[i].empty()) continue;
    std::vector<std::pair<size_t, size_t>> order(links[i].begin(), links[i].end());
    std::stable_sort(order.begin(), order.end(),
                     [](const auto& x, const auto& y) { return x.second > y.second; });
    for (const auto& [g, count] : order) {
      const uint32_t image = component.observations[i].image;
      if (std::any_of(groups[g].begin(), groups[g].end(),
                      [&](size_t m) { return component.observations[m].image == image; }))
        continue;
      if (!point[g]) point[g] = point_of(groups[g], views);
      if (!point[g]->allFinite() || !(error2_px(*views[i], *point[g], fx, fy) <= bound2)) continue;
      groups[g].push_back(i);
      used[i] = 1;
      break;
    }
  }
}

// Where an image has several observations within the bound (a repeated feature close by, and priors that
// drifted), the nearest through the priors may be the wrong one; the one with the most verified matches
// to the members in the other images is the track's. Ties keep the nearest.
void prefer_matched(Support& s, const std::vector<char>& used, const ObservationsByImage& index,
                    const io::SfmTrack& component, const std::vector<std::optional<TriangulationView>>& views,
                    const std::vector<std::vector<size_t>>& adjacent, double fx, double fy, double bound2) {
  std::vector<char> member(component.observations.size(), 0);
  for (size_t m : s.members) member[m] = 1;
  for (size_t& chosen : s.members) {
    const uint32_t image = component.observations[chosen].image;
    auto matched = [&](size_t i) {
      size_t count = 0;
      for (size_t j : adjacent[i]) count += member[j] && component.observations[j].image != image;
      return count;
    };
    size_t best = chosen, best_count = matched(chosen);
    std::vector<size_t> candidates;  // in index order, as the nearest wins a tie
    index.near(index.slot_of(chosen), s.X, [&](size_t i) { candidates.push_back(i); });
    std::sort(candidates.begin(), candidates.end());
    for (size_t i : candidates) {
      if (i == chosen || used[i]) continue;
      if (!(error2_px(*views[i], s.X, fx, fy) <= bound2)) continue;
      const size_t count = matched(i);
      if (count > best_count) {
        best = i;
        best_count = count;
      }
    }
    member[chosen] = 0;
    member[best] = 1;
    chosen = best;
  }
}

}  // namespace

void ConflictOptions::check() const {
  if (!(max_error_px > 0)) throw std::invalid_argument("conflicts.max_error_px must be > 0");
  if (!(merge_factor >= 0)) throw std::invalid_argument("conflicts.merge_factor must be >= 0");
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
  std::vector<std::vector<size_t>> adjacent(n);
  for (const auto& e : edges)
    if (e[0] < n && e[1] < n) {
      adjacent[e[0]].push_back(e[1]);
      adjacent[e[1]].push_back(e[0]);
    }
  std::vector<std::array<size_t, 2>> open = edges;
  ConflictSplit out;
  std::vector<std::vector<size_t>> groups;  // the tracks as observation indices
  const double bound2 = o.max_error_px * o.max_error_px;
  const ObservationsByImage index(component, views, fx, fy, o.max_error_px);
  while (true) {
    std::erase_if(open, [&](const auto& e) {
      return e[0] >= n || e[1] >= n || used[e[0]] || used[e[1]] || !views[e[0]] || !views[e[1]];
    });
    if (open.empty()) break;
    const size_t step = std::max<size_t>(1, open.size() / o.max_hypotheses);
    Support best;
    for (size_t h = 0; h < open.size(); h += step) {
      const Eigen::Vector3d X = triangulate_linear({*views[open[h][0]], *views[open[h][1]]}, {0, 1});
      if (!X.allFinite()) continue;
      Support s = support_of(X, used, index, views, fx, fy, bound2);
      // Both ends of the hypothesis must agree with their own point (not behind a camera).
      if (std::find(s.members.begin(), s.members.end(), open[h][0]) == s.members.end() ||
          std::find(s.members.begin(), s.members.end(), open[h][1]) == s.members.end())
        continue;
      if (s.members.size() > best.members.size() ||
          (s.members.size() == best.members.size() && s.error2_sum < best.error2_sum))
        best = std::move(s);
    }
    if (best.members.size() < 2) break;
    // A two-view point from a short baseline is poorly placed in depth, so distant views of the same point
    // fall outside the bound and would become a second track. Re-triangulating from every member and
    // collecting again (local optimisation, as in LO-RANSAC) keeps them in one.
    for (int round = 0; round < 3; ++round) {
      const Eigen::Vector3d X = point_of(best.members, views);
      if (!X.allFinite()) break;
      Support grown = support_of(X, used, index, views, fx, fy, bound2);
      if (grown.members.size() <= best.members.size()) break;
      best = std::move(grown);
    }
    prefer_matched(best, used, index, component, views, adjacent, fx, fy, bound2);
    for (size_t m : best.members) used[m] = 1;
    groups.push_back(std::move(best.members));
  }
  merge_disjoint_groups(groups, edges, component, views, fx, fy, o);
  attach_dropped(groups, used, edges, component, views, fx, fy, o);
  for (const auto& g : groups) {
    if (g.empty()) continue;
    io::SfmTrack t;
    for (size_t m : g) t.observations.push_back(component.observations[m]);
    std::sort(t.observations.begin(), t.observations.end(),
              [](const auto& a, const auto& b) { return a.image < b.image; });
    out.tracks.push_back(std::move(t));
  }
  for (size_t i = 0; i < n; ++i) out.dropped += !used[i];
  return out;
}

}  // namespace litgs::host::frontend
