// The frame of a written model. Training runs in the scene's recentred frame (scene = original world -
// world_offset_m, docs/scene-format.md), where float32 keeps sub-millimetre detail. point_cloud.ply is
// written in the original world frame unless TrainOptions::recentred_output, and its header says which:
//   comment litgs_world_offset_m X Y Z         model coordinates + (X, Y, Z) = original world coordinates
//   comment litgs_scene_world_offset_m A B C   the training scene's world_offset_m (scene + (A, B, C) =
//   original)
// A PLY without these lines (another trainer's) is taken to be in original world coordinates, its scene
// offset unknown.
#pragma once

#include <Eigen/Core>
#include <filesystem>
#include <optional>
#include <string>
#include <vector>

#include "kernels/splat/splat_types.h"

namespace litgs::host {

struct ModelFrame {
  Eigen::Vector3d world_offset_m = Eigen::Vector3d::Zero();  // model coordinates + this = original world
  std::optional<Eigen::Vector3d> scene_world_offset_m;       // the training scene's offset, where known
};

// The header comments that state `frame` (write_gaussian_ply's `comments`).
std::vector<std::string> model_frame_comments(const ModelFrame& frame);
// The frame a PLY's header states (see above); io::IoError naming the file for a malformed line.
ModelFrame read_model_frame(const std::filesystem::path& ply);

// The model with `delta` added to every mean, in double and rounded once to float: at 1000 m from the origin
// a float32 resolves ~6e-5 m, so a model written in original coordinates far from the origin keeps that
// precision. Components of `delta` that are exactly 0 leave their coordinate's bits untouched.
kernels::GaussianModel shift_means(kernels::GaussianModel model, const Eigen::Vector3d& delta);

}  // namespace litgs::host
