#include "host/frontend/tracks.h"

#include <algorithm>
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
  // False (nothing changed) if the components share an image.
  bool unite(size_t a, size_t b) {
    a = find(a);
    b = find(b);
    if (a == b) return true;
    std::vector<uint32_t>& ia = images_[a];
    std::vector<uint32_t>& ib = images_[b];
    std::vector<uint32_t> merged;
    std::set_union(ia.begin(), ia.end(), ib.begin(), ib.end(), std::back_inserter(merged));
    if (merged.size() != ia.size() + ib.size()) return false;
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
                      const std::vector<std::vector<uint32_t>>& representatives) {
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
  for (const auto& p : pairs)
    for (const auto& m : p.matches) {
      if (!m.inlier) continue;
      const size_t a = global(p.image_a, m.keypoint_a), b = global(p.image_b, m.keypoint_b);
      if (c.unite(a, b)) {
        used[a] = used[b] = 1;
      } else {
        ++out.conflicts;
      }
    }
  // Group keypoints by root, in keypoint order (so by image, then keypoint).
  std::vector<int64_t> track_of_root(offset.back(), -1);
  for (size_t i = 0; i < keypoints_per_image.size(); ++i)
    for (size_t k = offset[i]; k < offset[i + 1]; ++k) {
      if (!used[k]) continue;
      const size_t root = c.find(k);
      if (track_of_root[root] < 0) {
        track_of_root[root] = static_cast<int64_t>(out.tracks.size());
        out.tracks.emplace_back();
      }
      out.tracks[static_cast<size_t>(track_of_root[root])].observations.push_back(
          {static_cast<uint32_t>(i), static_cast<uint32_t>(k - offset[i])});
    }
  return out;
}

}  // namespace litgs::host::frontend
