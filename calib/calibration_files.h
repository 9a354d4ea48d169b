// What `calib intrinsics` writes: the camera block of scene.yaml, an OpenCV/ROS camera_info YAML, and one
// JSON object of the result; each file atomically.
#pragma once

#include <filesystem>
#include <nlohmann/json.hpp>
#include <string>

#include "calib/intrinsics.h"

namespace litgs::calib {

// {fx, fy, cx, cy, model, distortion, rms_px, views_used, coverage, stddev, views: [...], notes}.
nlohmann::json intrinsics_json(const IntrinsicsResult& result);

// PATH: scene.yaml's `camera:` block. PATH's stem + "_camera_info.yaml" beside it: ROS's camera_info
// (plumb_bob or equidistant). Returns the camera_info path.
std::filesystem::path write_intrinsics_files(const std::filesystem::path& path,
                                             const IntrinsicsResult& result);

}  // namespace litgs::calib
