// Descriptor matching: mutual nearest neighbours that also pass the ratio test.
#pragma once

#include <array>
#include <cstdint>
#include <vector>

#include "host/frontend/features.h"

namespace litgs::host::frontend {

struct MatchOptions {
  double ratio = 0.8;  // best distance < ratio * second best (in a's search over b)
  void check() const;  // std::invalid_argument
};

// Pairs (index in a, index in b): b's nearest to a's keypoint is it, and a's nearest to that is the same,
// and the ratio test holds. Empty if either side has no descriptors; invalid_argument if their kinds differ.
std::vector<std::array<uint32_t, 2>> match_mutual(const ImageFeatures& a, const ImageFeatures& b,
                                                  const MatchOptions& options);

// The same among allowed candidates only: allowed[i] lists the keypoints of b that a's keypoint i may match
// (e.g. those near its prior epipolar line), and b's keypoint j may match the i whose lists hold j.
// Nearest, second nearest and the mutual check are taken within these lists.
std::vector<std::array<uint32_t, 2>> match_mutual_among(const ImageFeatures& a, const ImageFeatures& b,
                                                        const std::vector<std::vector<uint32_t>>& allowed,
                                                        const MatchOptions& options);

}  // namespace litgs::host::frontend
