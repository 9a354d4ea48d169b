// The training views of a scene: cameras at the training resolution and target images in [0, 1].
#pragma once

#include <Eigen/Core>
#include <cstdint>
#include <filesystem>
#include <string>
#include <vector>

#include "host/frontend/intensity.h"
#include "io/scene.h"
#include "kernels/splat/splat_types.h"

namespace litgs::host {

enum class IntensityMapping {
  kAuto,        // percentile stretch for 16-bit frames, value / 255 for 8-bit ones
  kPercentile,  // robust stretch shared by all frames: [low, high] percentiles -> [0, 1], clamped
  kLinear,      // value / (2^bits - 1)
};

struct TrainingDataOptions {
  double downscale = 1.0;      // images and intrinsics divided by this (>= 1)
  uint32_t holdout_every = 8;  // frames i with i % holdout_every == 0 are held out (0: none)
  IntensityMapping mapping = IntensityMapping::kAuto;
  double low_percentile = 0.5;  // of all frames' raw values together, not per frame
  double high_percentile = 99.5;
  // Frames whose mean absolute difference to the previous kept frame is below this fraction of the
  // stretch range are frozen by the camera's non-uniformity correction and skipped.
  double frozen_threshold = 1e-4;
  // Poses are matched to frames by timestamp; farther than this they are interpolated, and outside the
  // trajectory an error.
  double pose_match_tolerance_s = 1e-3;
  // Train on the scene's ground-truth poses (gt/poses.txt) instead of poses.txt: synthetic experiments that
  // separate a loss's effect from the estimator's pose drift. An error if the scene has none.
  bool true_poses = false;
  void check() const;  // throws std::invalid_argument naming the bad field
};

// The stretch that maps raw values to [0, 1] when training maps by percentiles: the scene's
// intensity_window where it has one, else the options' percentiles of all frames' values together
// (`all_frames`). `partition` records it as every block's window, so that the blocks map as one training of
// the whole scene does.
frontend::Stretch percentile_window(const io::SceneConfig& config, const frontend::Histogram& all_frames,
                                    const TrainingDataOptions& options);

struct TrainingView {
  std::string name;  // the frame's file name
  double t_s = 0;
  kernels::SplatCamera camera;  // pinhole, undistorted, at the training resolution
  std::vector<float> image;     // [H][W] target in [0, 1]
  bool heldout = false;
  // Frames frozen by the camera's non-uniformity correction were skipped right before this one: its level
  // may jump (the level model does not smooth across it).
  bool after_frozen = false;
};

struct TrainingData {
  TrainingDataOptions
      options;  // what load_training_data was given (stored in checkpoints, compared on resume)
  std::vector<TrainingView> views;
  double stretch_low = 0, stretch_high = 1;                  // raw values mapped to 0 and 1
  Eigen::Vector3d world_offset_m = Eigen::Vector3d::Zero();  // scene world = original world - offset
  double scene_extent_m = 1;  // 1.1 x the largest camera-centre distance from their mean (3DGS)
  size_t frozen_skipped = 0;
  uint32_t width = 0, height = 0;  // training resolution
};

// Reads the scene directory, maps intensities, undistorts (radtan k1 k2 p1 p2 [k3]) and downscales.
// Throws io::IoError / std::invalid_argument naming the file or the problem.
TrainingData load_training_data(const std::filesystem::path& scene_dir, const TrainingDataOptions& options);

// The cameras of the views training fits (held-out views left out), in view order.
std::vector<kernels::SplatCamera> training_cameras(const TrainingData& data);

// The camera training uses for the frame at `t_s` of `scene` (read from `scene_dir`), in the scene's
// (recentred) frame: the pose at that time in poses.txt (gt/poses.txt with options.true_poses), matched
// within pose_match_tolerance_s or interpolated and moved from the IMU to the camera where the poses are the
// IMU's; the undistorted pinhole intrinsics at the training resolution (options.downscale). Throws
// std::invalid_argument for a time outside the trajectory.
kernels::SplatCamera training_camera(const std::filesystem::path& scene_dir, const io::Scene& scene,
                                     double t_s, const TrainingDataOptions& options);

}  // namespace litgs::host
