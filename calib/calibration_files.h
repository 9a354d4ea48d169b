// What `calib intrinsics` and `calib extrinsic` write: the camera block of scene.yaml, an OpenCV/ROS
// camera_info YAML, and one JSON object of the result; each file atomically.
#pragma once

#include <filesystem>
#include <nlohmann/json.hpp>
#include <string>

#include "calib/extrinsic.h"
#include "calib/intrinsics.h"

namespace litgs::calib {

// {fx, fy, cx, cy, model, distortion, rms_px, views_used, coverage, stddev, views: [...], notes}.
nlohmann::json intrinsics_json(const IntrinsicsResult& result);

// PATH: scene.yaml's `camera:` block. PATH's stem + "_camera_info.yaml" beside it: ROS's camera_info
// (plumb_bob or equidistant). Returns the camera_info path.
std::filesystem::path write_intrinsics_files(const std::filesystem::path& path,
                                             const IntrinsicsResult& result);

// {T_cam_lidar (4 rows), rms_px, rms_m, rotation_sd_deg, translation_sd_m, views_used, views: [...]}.
nlohmann::json extrinsic_json(const ExtrinsicResult& result);

// PATH: scene.yaml's `T_cam_lidar:` block, with the residuals in a comment.
void write_extrinsic_yaml(const std::filesystem::path& path, const ExtrinsicResult& result);

// The scene.yaml at PATH with its T_cam_lidar replaced (read and written through io/scene_yaml, atomically).
void write_extrinsic_into_scene(const std::filesystem::path& scene_yaml, const ExtrinsicResult& result);

}  // namespace litgs::calib
