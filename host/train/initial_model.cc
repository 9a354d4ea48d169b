#include "host/train/initial_model.h"

#include <algorithm>
#include <random>
#include <stdexcept>

#include "host/train/init_gaussians.h"
#include "host/train/scene_budget.h"
#include "io/sfm_files.h"

namespace litgs::host {

InitialModel::InitialModel(const InitialModelOptions& o, const std::filesystem::path& scene_dir,
                           const std::vector<Eigen::Vector3d>& map_points, bool resume)
    : options_(o), sfm_dir_(scene_dir / "sfm"), map_points_(map_points) {
  if (resume) {
    source_ = InitialSource::kCheckpoint;
    return;
  }
  sfm_present_ = io::has_sfm(sfm_dir_);
  if ((o.init == "sfm" || (o.init == "auto" && map_points.empty())) && sfm_present_)
    for (const io::SfmPoint& p : io::read_sfm(sfm_dir_).points) sfm_points_.push_back(p.xyz);
  if (o.init == "auto")
    source_ = !map_points.empty()    ? InitialSource::kMap
              : !sfm_points_.empty() ? InitialSource::kSfm
                                     : InitialSource::kRandom;
  else if (o.init == "random")
    source_ = InitialSource::kRandom;
  else if (o.init == "sfm")
    source_ = InitialSource::kSfm;
  else
    source_ = InitialSource::kFile;
}

kernels::GaussianModel InitialModel::make(const TrainingData& data, const PlanarMap* planes,
                                          uint32_t cap_gaussians, std::string& what) const {
  InitOptions init;
  init.sh_degree = options_.sh_degree;
  switch (source_) {
    case InitialSource::kCheckpoint:
      what = "the newest checkpoint";
      return {};
    case InitialSource::kRandom:
      what = std::to_string(options_.random_count) + " random points";
      return init_random(data, options_.random_count, options_.seed, init);
    case InitialSource::kMap: {
      if (!planes) throw std::logic_error("InitialModel::make: a map seeding needs the map's plane fit");
      // Planar map points become discs on their plane (the plane fit's normal), the rest spheres. Only the
      // points a training view sees (a Gaussian none sees is never trained), and never more than the budget
      // or max_init_points: a seeded random subset.
      const std::vector<uint8_t> seen = inside_any_view(map_points_, training_cameras(data));
      std::vector<size_t> keep;
      for (size_t i = 0; i < map_points_.size(); ++i)
        if (seen[i]) keep.push_back(i);
      if (keep.empty())  // no view sees the map (bad poses?): seed from all of it rather than nothing
        for (size_t i = 0; i < map_points_.size(); ++i) keep.push_back(i);
      const size_t cap = std::min<size_t>(options_.max_init_points, cap_gaussians);
      if (keep.size() > cap) {
        std::mt19937 rng(options_.seed);
        std::shuffle(keep.begin(), keep.end(), rng);
        keep.resize(cap);
      }
      std::vector<Eigen::Vector3d> points;
      std::vector<Eigen::Vector3f> normals;
      std::vector<uint8_t> planar;
      for (size_t i : keep) {
        points.push_back(map_points_[i]);
        normals.push_back(planes->normals[i]);
        planar.push_back(planes->planar[i]);
      }
      const auto covariances = surfel_covariances(neighbour_scales(points, init, data.scene_extent_m * 0.01),
                                                  normals, planar, options_.init_flatness);
      what = std::to_string(points.size()) + " LiDAR map points";
      return init_from_points(points, data, init, covariances);
    }
    case InitialSource::kSfm:
      // The front end's triangulated points, already in the scene's recentred frame.
      if (sfm_points_.empty())
        throw std::invalid_argument("--init sfm: " + sfm_dir_.string() +
                                    (sfm_present_
                                         ? " holds no triangulated point"
                                         : " holds no front-end results (run `litgs-engine match` first)"));
      what = std::to_string(sfm_points_.size()) + " front-end points (" + sfm_dir_.string() + ")";
      return init_from_points(sfm_points_, data, init, {});
    case InitialSource::kFile: {
      const InitPoints file = load_points(
          options_.init, options_.init_in_scene_frame ? Eigen::Vector3d::Zero() : data.world_offset_m);
      what = options_.init + (file.covariances.empty() ? "" : " (with covariances)");
      return init_from_points(file.positions, data, init, file.covariances);
    }
  }
  throw std::logic_error("InitialModel::make: unknown source");
}

}  // namespace litgs::host
