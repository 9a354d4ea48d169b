// Tracks: connected components of the verified matches (union-find), at most one keypoint per image.
#pragma once

#include <cstddef>
#include <vector>

#include "io/sfm_files.h"

namespace litgs::host::frontend {

struct TrackSet {
  std::vector<io::SfmTrack> tracks;  // length >= 2, observations sorted by image
  // Verified matches not joined because the two components already held another keypoint of a common
  // image (joining would put two keypoints of one image in a track): the later match is dropped.
  size_t conflicts = 0;
};

// Per image, each keypoint's representative: the first keypoint at exactly the same position (SIFT gives one
// keypoint per orientation at a location). Tracks join through representatives, so two orientations of one
// image location are one observation, not a conflict.
std::vector<std::vector<uint32_t>> same_location_representatives(
    const std::vector<std::vector<io::SfmKeypoint>>& keypoints);

// keypoints_per_image[i]: keypoint count of image i. Only matches flagged inlier are used, pair by pair in
// the given order (deterministic). invalid_argument for an index out of range.
// With `representatives` (same_location_representatives), keypoints are replaced by theirs first.
TrackSet build_tracks(const std::vector<size_t>& keypoints_per_image,
                      const std::vector<io::SfmPairMatches>& pairs,
                      const std::vector<std::vector<uint32_t>>& representatives = {});

}  // namespace litgs::host::frontend
