// The options `litgs-engine eval` shares with run.yaml's eval section (host/option_name.h).
#pragma once

#include "host/option_name.h"

namespace litgs::host::eval_option {

inline constexpr OptionName kEmdSamples{"emd_samples", "--emd-samples",
                                        "EMD: points drawn from each side (exact assignment, O(N^3))"};
inline constexpr OptionName kEmdRounds{"emd_rounds", "--emd-rounds", "EMD: independent draws (mean and std)"};
inline constexpr OptionName kSeed{"seed", "--seed", "EMD: seed of the draws"};
inline constexpr OptionName kGeometry{"geometry", "!--no-geometry",
                                      "EMD and the plane residuals (--no-geometry: skipped)"};

}  // namespace litgs::host::eval_option
