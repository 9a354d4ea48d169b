// What `render` and `serve` share so that one view renders to the same bytes through either: the rotation
// of a camera quaternion, the model moved into the frame the poses are given in, and float planes to PNG
// pixels.
#pragma once

#include <Eigen/Core>
#include <cstdint>
#include <filesystem>
#include <glm/glm.hpp>
#include <optional>
#include <string>
#include <vector>

#include "io/image.h"
#include "kernels/splat/splat_types.h"

namespace litgs::tools {

// The rotation of quaternion (w, x, y, z), normalized first; std::invalid_argument if it is zero or not
// finite.
glm::dmat3 rotation_from_quat(double w, double x, double y, double z);

// A 3DGS PLY moved into the frame its poses are given in (see cmd_render.cc's top comment).
struct FramedModel {
  kernels::GaussianModel model;
  std::string frame;                                       // "scene", "original" or "model"
  Eigen::Vector3d frame_offset = Eigen::Vector3d::Zero();  // pose-frame coordinates + this = original world
};
// pose_frame: auto | scene | original | model. scene_offset: the --scene's world_offset_m, if given (it wins
// over the PLY's header line, with a note on stderr when they differ).
FramedModel load_framed_model(const std::filesystem::path& ply, const std::string& pose_frame,
                              const std::optional<Eigen::Vector3d>& scene_offset,
                              const std::string& scene_name = "the scene");

// Planes [C][H][W] times `scale`, rounded and clamped to the bit depth (non-finite values: 0), interleaved.
io::Image to_image(const std::vector<float>& planes, uint32_t w, uint32_t h, uint32_t channels, int bit_depth,
                   double scale);

std::string vector_text(const Eigen::Vector3d& v);

}  // namespace litgs::tools
