// The options `litgs-engine map` shares with run.yaml's map section (host/option_name.h).
#pragma once

#include "host/option_name.h"

namespace litgs::host::map_option {

inline constexpr OptionName kVoxel{"voxel", "--voxel", "Voxel edge in metres (points averaged per voxel)"};
inline constexpr OptionName kDeskew{"deskew", "!--no-deskew",
                                    "Deskew scans with their per-point time field (--no-deskew: ignore it)"};

}  // namespace litgs::host::map_option
