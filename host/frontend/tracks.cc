#include "host/frontend/tracks.h"

#include <algorithm>
#include <array>
#include <map>
#include <numeric>
#include <stdexcept>
#include <string>

namespace litgs::host::frontend {
namespace {

// Union-find over all keypoints; each root keeps the sorted images its component touches.
class Components {
 public:
  explicit Components(size_t n) : parent_(n), images_(n) {
    std::iota(parent_.begin(), parent_.end(), size_t{0});
  }
  size_t find(size_t x) {
    while (parent_[x] != x) x = parent_[x] = parent_[parent_[x]];
    return x;
  }
  void set_image(size_t x, uint32_t image) { images_[x] = {image}; }
  // False (nothing changed) if the components share an image, unless `allow_conflict`.
  bool unite(size_t a, size_t b, bool allow_conflict = false) {
    a = find(a);
    b = find(b);
    if (a == b) return true;
    std::vector<uint32_t>& ia = images_[a];
    std::vector<uint32_t>& ib = images_[b];
    std::vector<uint32_t> merged;
    std::set_union(ia.begin(), ia.end(), ib.begin(), ib.end(), std::back_inserter(merged));
    if (!allow_conflict && merged.size() != ia.size() + ib.size()) return false;
    merged.erase(std::unique(merged.begin(), merged.end()), merged.end());
    if (ia.size() < ib.size()) std::swap(a, b);
    parent_[b] = a;
    images_[a] = std::move(merged);
    images_[b].clear();
    return true;
  }

 private:
  std::vector<size_t> parent_;
  std::vector<std::vector<uint32_t>> images_;
};

}  // namespace

std::vector<std::vector<uint32_t>> same_location_representatives(
    const std::vector<std::vector<io::SfmKeypoint>>& keypoints) {
  std::vector<std::vector<uint32_t>> out(keypoints.size());
  for (size_t i = 0; i < keypoints.size(); ++i) {
    std::map<std::pair<float, float>, uint32_t> first_at;
    for (uint32_t k = 0; k < keypoints[i].size(); ++k)
      out[i].push_back(first_at.try_emplace({keypoints[i][k].x, keypoints[i][k].y}, k).first->second);
  }
  return out;
}

TrackSet build_tracks(const std::vector<size_t>& keypoints_per_image,
                      const std::vector<io::SfmPairMatches>& pairs,
                      const std::vector<std::vector<uint32_t>>& representatives,
                      const ComponentSplitter& split) {
  std::vector<size_t> offset(keypoints_per_image.size() + 1, 0);
  for (size_t i = 0; i < keypoints_per_image.size(); ++i) offset[i + 1] = offset[i] + keypoints_per_image[i];
  Components c(offset.back());
  for (size_t i = 0; i < keypoints_per_image.size(); ++i)
    for (size_t k = offset[i]; k < offset[i + 1]; ++k) c.set_image(k, static_cast<uint32_t>(i));
  auto global = [&](uint32_t image, uint32_t keypoint) {
    if (image >= keypoints_per_image.size() || keypoint >= keypoints_per_image[image])
      throw std::invalid_argument("build_tracks: keypoint " + std::to_string(keypoint) + " of image " +
                                  std::to_string(image) + " out of range");
    if (image < representatives.size()) keypoint = representatives[image].at(keypoint);
    return offset[image] + keypoint;
  };
  TrackSet out;
  std::vector<char> used(offset.back(), 0);
  std::vector<std::array<size_t, 2>> joined;  // the matches (global keypoints) that were united
  for (const auto& p : pairs)
    for (const auto& m : p.matches) {
      if (!m.inlier) continue;
      const size_t a = global(p.image_a, m.keypoint_a), b = global(p.image_b, m.keypoint_b);
      if (a == b) continue;
      ++out.matches;
      if (c.unite(a, b, static_cast<bool>(split))) {
        used[a] = used[b] = 1;
        joined.push_back({a, b});
      } else {
        ++out.conflicts;
      }
    }
  // Group keypoints by root, in keypoint order (so by image, then keypoint).
  std::vector<int64_t> component_of_root(offset.back(), -1);
  std::vector<io::SfmTrack> components;
  std::vector<size_t> local(offset.back(), 0);  // a keypoint's index in its component
  for (size_t i = 0; i < keypoints_per_image.size(); ++i)
    for (size_t k = offset[i]; k < offset[i + 1]; ++k) {
      if (!used[k]) continue;
      const size_t root = c.find(k);
      if (component_of_root[root] < 0) {
        component_of_root[root] = static_cast<int64_t>(components.size());
        components.emplace_back();
      }
      auto& obs = components[static_cast<size_t>(component_of_root[root])].observations;
      local[k] = obs.size();
      obs.push_back({static_cast<uint32_t>(i), static_cast<uint32_t>(k - offset[i])});
    }
  if (!split) {
    out.tracks = std::move(components);
    return out;
  }
  std::vector<std::vector<std::array<size_t, 2>>> edges(components.size());
  for (const auto& [a, b] : joined)
    edges[static_cast<size_t>(component_of_root[c.find(a)])].push_back({local[a], local[b]});
  // The output track of each keypoint (-1: none), to count the matches the split separated.
  std::vector<int64_t> track_of(offset.back(), -1);
  for (size_t ci = 0; ci < components.size(); ++ci) {
    const io::SfmTrack& comp = components[ci];
    bool conflict = false;
    for (size_t k = 1; k < comp.observations.size(); ++k)
      conflict |= comp.observations[k].image == comp.observations[k - 1].image;
    std::vector<io::SfmTrack> pieces;
    if (conflict) {
      ConflictSplit parts = split(comp, edges[ci]);
      ++out.conflicting_components;
      out.conflict_observations_dropped += parts.dropped;
      out.conflict_observations_kept += comp.observations.size() - parts.dropped;
      pieces = std::move(parts.tracks);
    } else {
      pieces.push_back(comp);
    }
    for (auto& t : pieces) {
      std::sort(t.observations.begin(), t.observations.end(),
                [](const auto& x, const auto& y) { return x.image < y.image; });
      for (const auto& o : t.observations)
        track_of[offset[o.image] + o.keypoint] = static_cast<int64_t>(out.tracks.size());
      out.tracks.push_back(std::move(t));
    }
  }
  for (const auto& [a, b] : joined) out.conflicts += track_of[a] < 0 || track_of[a] != track_of[b];
  return out;
}

}  // namespace litgs::host::frontend
