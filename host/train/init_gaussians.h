// Initial Gaussians: from a point cloud (the refined or triangulated points, or the LiDAR map) or at random
// inside the scene, sized by their neighbours and coloured from the training views.
#pragma once

#include <Eigen/Core>
#include <cstdint>
#include <filesystem>
#include <optional>
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
// A file that carries the six fields cov_xx cov_xy cov_xz cov_yy cov_yz cov_zz (m^2, the upper triangle of
// each point's 3x3 covariance, the order of anchors.txt) gives them too; a point whose covariance is not
// finite and positive definite is an error naming it.
struct InitPoints {
  std::vector<Eigen::Vector3d> positions;
  std::vector<Eigen::Matrix3d> covariances;  // [N] or empty
};
InitPoints load_points(const std::filesystem::path& file, const Eigen::Vector3d& world_offset_m);

// RMS distance of each point to its `neighbours` nearest others, at least min_scale_m (3DGS's initial scale);
// isolated_scale_m for a point with no other (a one-point cloud).
std::vector<double> neighbour_scales(const std::vector<Eigen::Vector3d>& points, const InitOptions& options,
                                     double isolated_scale_m = 0.0);

// Gaussians at the points. With a covariance (covariances non-empty: one per point), the Gaussian takes its
// axes and their lengths (the square roots of its eigenvalues, at least min_scale_m): anisotropic; without,
// an isotropic Gaussian of neighbour_scales() size and a unit quaternion. The DC term from bilinear sampling
// of the nearest training view that sees the point (0.5 gray where none does); higher SH coefficients zero.
kernels::GaussianModel init_from_points(const std::vector<Eigen::Vector3d>& points, const TrainingData& data,
                                        const InitOptions& options,
                                        const std::vector<Eigen::Matrix3d>& covariances = {});

// A thin disc per point that lies on a LiDAR plane: radius `scale` in the plane, `flatness * scale` along
// its normal n (covariance s^2 (I - n n^T) + (flatness s)^2 n n^T); an isotropic s^2 I elsewhere. For the
// LiDAR-map initialization: a Gaussian centred on a plane then renders that plane's depth at every pixel it
// covers, where an isotropic one renders its centre's depth across a slanted footprint.
std::vector<Eigen::Matrix3d> surfel_covariances(const std::vector<double>& scales,
                                                const std::vector<Eigen::Vector3f>& normals,
                                                const std::vector<uint8_t>& planar, double flatness);

// `count` points uniform in the cube of side 2 x scene extent around the mean camera centre, then as above.
kernels::GaussianModel init_random(const TrainingData& data, uint32_t count, uint32_t seed,
                                   const InitOptions& options);

}  // namespace litgs::host
