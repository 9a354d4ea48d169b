// scene.yaml: read strictly (yaml-cpp, hidden here), written by hand so numbers round-trip exactly and the
// file carries comments.
#pragma once

#include <filesystem>
#include <string>

#include "io/scene_types.h"

namespace litgs::io {

// IoError (file, line, problem) on: a missing file, YAML syntax, a missing or unknown key, a wrong type, a
// non-finite number, units other than m/s/rad, an unknown camera model or pose frame, a distortion of the
// wrong length for the model, a bit depth other than 8/16, non-positive size or focal length, a transform
// that is not 4x4 rigid.
SceneConfig read_scene_yaml(const std::filesystem::path& path);
// Throws std::invalid_argument naming the field on the same checks; writes atomically.
void write_scene_yaml(const std::filesystem::path& path, const SceneConfig& config);

// The `camera:` block of a file: camera.yaml as `calib intrinsics` writes it, or a scene.yaml. IoError as
// read_scene_yaml gives for that block.
CameraIntrinsics read_camera_yaml(const std::filesystem::path& path);

// scene.yaml's `camera:` block, as write_scene_yaml writes it (`calib intrinsics` writes it alone).
std::string camera_yaml_block(const CameraIntrinsics& camera);

// The checks shared by reader and writer: empty if valid, else "FIELD: problem".
std::string check_scene_config(const SceneConfig& config);

}  // namespace litgs::io
