// Tracks: connected components of the verified matches (union-find), at most one keypoint per image. A
// component that would hold two keypoints of one image (a conflict) is split by a ComponentSplitter when
// one is given (track_conflicts.h: by the prior poses), else the later match is refused.
#pragma once

#include <array>
#include <cstddef>
#include <functional>
#include <vector>

#include "host/frontend/track_conflicts.h"
#include "io/sfm_files.h"

namespace litgs::host::frontend {

struct TrackSet {
  std::vector<io::SfmTrack> tracks;  // length >= 2, observations sorted by image
  // Verified matches not joined because the two components already held another keypoint of a common
  // image (joining would put two keypoints of one image in a track): the later match is dropped.
  // With a splitter: the verified matches whose two keypoints did not end in one track (lost to conflicts).
  size_t conflicts = 0;
  size_t matches = 0;                 // verified matches between distinct keypoints (the denominator)
  size_t conflicting_components = 0;  // with a splitter: components split
  size_t conflict_observations_kept = 0, conflict_observations_dropped = 0;  // their keypoints
};

// Splits one conflicting component (observations sorted by image) given its matches as index pairs.
using ComponentSplitter = std::function<ConflictSplit(const io::SfmTrack& component,
                                                      const std::vector<std::array<size_t, 2>>& edges)>;

// Per image, each keypoint's representative: the first keypoint at exactly the same position (SIFT gives one
// keypoint per orientation at a location). Tracks join through representatives, so two orientations of one
// image location are one observation, not a conflict.
std::vector<std::vector<uint32_t>> same_location_representatives(
    const std::vector<std::vector<io::SfmKeypoint>>& keypoints);

// keypoints_per_image[i]: keypoint count of image i. Only matches flagged inlier are used, pair by pair in
// the given order (deterministic). invalid_argument for an index out of range.
// With `representatives` (same_location_representatives), keypoints are replaced by theirs first.
// With `split`, components form without refusal and every conflicting one is split.
TrackSet build_tracks(const std::vector<size_t>& keypoints_per_image,
                      const std::vector<io::SfmPairMatches>& pairs,
                      const std::vector<std::vector<uint32_t>>& representatives = {},
                      const ComponentSplitter& split = {});

}  // namespace litgs::host::frontend
