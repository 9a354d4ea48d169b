// Initial Gaussians: from a point cloud (the refined or triangulated points, or the LiDAR map) or at random
// inside the scene, sized by their neighbours and coloured from the training views.
#pragma once

#include <Eigen/Core>
#include <cstdint>
#include <filesystem>
#include <vector>

#include "host/train/training_data.h"
#include "kernels/splat/splat_types.h"

namespace litgs::host {

struct InitOptions {
  uint32_t sh_degree = 3;        // degree of the model (the trainer ramps the active degree up to it)
  float initial_opacity = 0.1f;  // 3DGS's initial opacity
  uint32_t neighbours = 3;       // scale = RMS distance to this many nearest neighbours (3DGS: 3)
  double min_scale_m = 1e-4;     // floor of that distance (duplicate points)
  void check() const;            // throws std::invalid_argument naming the bad field
};

// Points of a PLY or PCD file (by extension) in the scene's world frame: the file's coordinates minus the
// scene's recentring offset. IoError on bad files; std::invalid_argument on an empty cloud.
std::vector<Eigen::Vector3d> load_points(const std::filesystem::path& file, const Eigen::Vector3d& world_offset_m);

// Isotropic Gaussians at the points; the DC term from bilinear sampling of the nearest training view that
// sees the point (0.5 gray where none does); higher SH coefficients zero; unit quaternions.
kernels::GaussianModel init_from_points(const std::vector<Eigen::Vector3d>& points, const TrainingData& data,
                                        const InitOptions& options);

// `count` points uniform in the cube of side 2 x scene extent around the mean camera centre, then as above.
kernels::GaussianModel init_random(const TrainingData& data, uint32_t count, uint32_t seed, const InitOptions& options);

}  // namespace litgs::host
