// Descriptor matching: mutual nearest neighbours that also pass the ratio test (kRatio, for the classical
// detectors) or whose cosine similarity exceeds a bound (kMnn, XFeat's matcher: unit-length float
// descriptors); or a learned matcher that sees both images' keypoints and descriptors at once (kLighterGlue,
// a LearnedMatcher: host/nn/lighterglue_matcher.h).
#pragma once

#include <array>
#include <cstdint>
#include <functional>
#include <string>
#include <vector>

#include "host/frontend/features.h"

namespace litgs::host::frontend {

enum class Matcher { kRatio, kMnn, kLighterGlue };
std::string matcher_name(Matcher matcher);
Matcher parse_matcher(const std::string& name);  // "ratio" | "mnn" | "lighterglue"; invalid_argument

struct MatchOptions {
  Matcher matcher = Matcher::kRatio;
  double ratio = 0.8;        // kRatio: best distance < ratio * second best (in a's search over b)
  double min_cosine = 0.82;  // kMnn: the pair's cosine similarity above this (XFeat's default)
  double min_score = 0.1;    // kLighterGlue: a mutual pair's assignment probability above this (XFeat's)
  void check() const;        // std::invalid_argument
};

// Pairs (index in a, index in b): b's nearest to a's keypoint is it, and a's nearest to that is the same,
// and the ratio test (kRatio) or the cosine bound (kMnn) holds. Empty if either side has no descriptors;
// invalid_argument if their kinds differ, or kMnn is asked of bit-string descriptors.
std::vector<std::array<uint32_t, 2>> match_mutual(const ImageFeatures& a, const ImageFeatures& b,
                                                  const MatchOptions& options);

// The same among allowed candidates only: allowed[i] lists the keypoints of b that a's keypoint i may match
// (e.g. those near its prior epipolar line), and b's keypoint j may match the i whose lists hold j.
// Nearest, second nearest and the mutual check are taken within these lists.
std::vector<std::array<uint32_t, 2>> match_mutual_among(const ImageFeatures& a, const ImageFeatures& b,
                                                        const std::vector<std::vector<uint32_t>>& allowed,
                                                        const MatchOptions& options);

// A matcher that runs outside this library (a network on the Vulkan device): pairs (index in a, index in
// b) for two images of width x height pixels; called from several threads at once.
using LearnedMatcher = std::function<std::vector<std::array<uint32_t, 2>>(
    const ImageFeatures& a, const ImageFeatures& b, int width, int height)>;

}  // namespace litgs::host::frontend
