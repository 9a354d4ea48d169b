// The Gaussians a training starts from (`train --init`): the policy that picks the source and seeds a
// model from it. auto: the scene's LiDAR map when it has one, else the front end's points (SCENE/sfm/ from
// `match`), else random points in the training views.
#pragma once

#include <Eigen/Core>
#include <cstdint>
#include <filesystem>
#include <string>
#include <vector>

#include "host/train/lidar_planes.h"
#include "host/train/training_data.h"
#include "kernels/splat/splat_types.h"

namespace litgs::host {

struct InitialModelOptions {
  std::string init = "auto";  // auto | random | sfm | a .ply/.pcd file (in the scene's original world frame)
  bool init_in_scene_frame = false;   // the file is in the recentred scene frame
  uint32_t random_count = 20000;      // Gaussians of init random
  uint32_t max_init_points = 200000;  // LiDAR-map initialization keeps at most this many points
  // LiDAR-map initialization: a point on a LiDAR plane becomes a disc this thin relative to its radius
  // (surfel_covariances); 1: spheres, as 3DGS.
  double init_flatness = 0.1;
  uint32_t seed = 0;       // the subset of map points, the random points
  uint32_t sh_degree = 3;  // of the model made
};

enum class InitialSource { kCheckpoint, kMap, kSfm, kRandom, kFile };

class InitialModel {
 public:
  // Picks the source. `resume`: the model comes from the training's checkpoint and no option applies.
  // Reads SCENE/sfm/ when the source is (or, under auto without a map, may be) the front end's points.
  InitialModel(const InitialModelOptions& options, const std::filesystem::path& scene_dir,
               const std::vector<Eigen::Vector3d>& map_points, bool resume);

  InitialSource source() const { return source_; }
  bool from_map() const { return source_ == InitialSource::kMap; }

  // The model for a budget of `cap_gaussians` (a map seeding keeps at most that many points; the budget
  // search seeds each budget it tries the same way) and what it was made from. `planes`: the map's plane
  // fit, needed when from_map(). Nothing for kCheckpoint. std::invalid_argument for sfm without points.
  kernels::GaussianModel make(const TrainingData& data, const PlanarMap* planes, uint32_t cap_gaussians,
                              std::string& what) const;

 private:
  InitialModelOptions options_;
  std::filesystem::path sfm_dir_;
  const std::vector<Eigen::Vector3d>& map_points_;
  std::vector<Eigen::Vector3d> sfm_points_;
  bool sfm_present_ = false;
  InitialSource source_ = InitialSource::kRandom;
};

}  // namespace litgs::host
