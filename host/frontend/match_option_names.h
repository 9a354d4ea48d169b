// The options `litgs-engine match` shares with run.yaml's match section (host/option_name.h).
#pragma once

#include "host/option_name.h"

namespace litgs::host::match_option {

inline constexpr OptionName kFeatures{"features", "--features",
                                      "orb | sift | akaze | xfeat (XFeat on the Vulkan device)"};
inline constexpr OptionName kMatcher{
    "matcher", "--matcher",
    "auto (ratio; mnn for xfeat) | ratio (mutual nearest + ratio test) | mnn "
    "(mutual nearest + cosine bound) | lighterglue (XFeat's learned matcher on the device; xfeat only)"};
inline constexpr OptionName kClahe{"clahe", "!--no-clahe", "CLAHE before detection (--no-clahe: none)"};
inline constexpr OptionName kPairs{
    "pairs", "--pairs",
    "covisible[:N] (sequential:N first, then frusta that overlap at the scene depth) | sequential:N | "
    "exhaustive"};
inline constexpr OptionName kMaxKeypoints{"max_keypoints", "--max-keypoints", "Keypoint budget per image"};
inline constexpr OptionName kThreads{"threads", "--threads", "Worker threads (0: all cores)"};
inline constexpr OptionName kXfeatScale{
    "xfeat_scale", "--xfeat-scale",
    "xfeat: run the network on the frame resized by this factor (then to multiples of 32); keypoints are "
    "given in the frame's pixels"};

}  // namespace litgs::host::match_option
