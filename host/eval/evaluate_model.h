// `litgs-engine eval`: a trained model against its scene. Rendering quality on the held-out views (the views
// training held out, at the training resolution and intensity mapping), geometry against the reference cloud
// (EMD) and planes, and speed. Units:
// - images: intensity in [0, 1] as training maps the frames (host/train/training_data.h: 8-bit frames value /
//   255; 16-bit frames stretched from raw counts [stretch_low, stretch_high] to [0, 1], clamped). PSNR with
//   peak 1 and SSIM (the 11-tap Gaussian-window, sigma 1.5, SSIM of 3DGS), as the trainer's evaluation,
//   both on the render clamped to [0, 1] as `render` writes it: an image cannot show a value outside the
//   range. The 8- or 16-bit quantization of a written image is not applied. For 16-bit data also the mean
//   absolute error in raw counts: the [0, 1] error times (stretch_high - stretch_low), against the frame as
//   training sees it (clamped to the stretch).
// - co-visibility (scenes with true depth, as synthetic ones): PSNR over the held-out pixels some training
//   view also sees (host/eval/covisibility.h), beside the PSNR over every pixel.
// - geometry: metres, in the scene's frame, against gt/map.pcd, else the scans the LiDAR map held out
//   (lidar/heldout.pcd), else the training map itself (circular: said in the output). EMD and the coverage
//   are restricted to the region the training views observe (host/eval/observed_region.h).
// LPIPS is not computed: it needs pretrained network weights that this project cannot obtain.
#pragma once

#include <cstdint>
#include <filesystem>
#include <nlohmann/json.hpp>
#include <optional>
#include <string>
#include <vector>

#include "host/eval/emd.h"
#include "host/eval/observed_region.h"
#include "host/train/training_data.h"

namespace litgs::host {

struct EvalOptions {
  TrainingDataOptions data;  // must be the training run's (downscale, holdout_every, intensity, poses)
  EmdOptions emd;
  ObservedRegionOptions region;
  bool geometry = true;  // EMD and plane residuals (needs a reference cloud)
  void check() const;    // std::invalid_argument naming the bad field
};

struct ViewMetrics {
  std::string name;
  double t_s = 0;
  double psnr_db = 0, ssim = 0;
  double mae_counts = -1;          // 16-bit data only; -1 otherwise
  double depth_plane_rmse_m = -1;  // where planes exist; -1 otherwise
  double render_ms = 0;            // forward and readback, wall clock
  // Where the scene has true depth (host/eval/covisibility.h): the share of the view's pixels that a
  // training view also sees, and the PSNR over those (NaN if none); -1 otherwise.
  double covisible_fraction = -1, covisible_psnr_db = -1;
};

// One held-out view's images at the training resolution (row-major [H][W]).
struct ViewImages {
  std::string name;
  uint32_t width = 0, height = 0;
  std::vector<float> render, target, depth_m, alpha;
  std::vector<uint8_t> covisible;  // [H][W] 1 where a training view saw the surface; empty: not measured
};

struct ModelEvaluation {
  std::vector<ViewMetrics> views;
  double psnr_db = 0, ssim = 0, mae_counts = -1, depth_plane_rmse_m = -1;  // means over the views
  // Means over the views (covisible_psnr_db over those with a covisible pixel); -1 where not measured, and
  // covisibility_unavailable says why.
  double covisible_fraction = -1, covisible_psnr_db = -1;
  std::string covisibility_unavailable;
  double render_ms_median = 0;
  uint32_t width = 0, height = 0;
  int bit_depth = 8;
  double stretch_low = 0, stretch_high = 1;
  size_t gaussians = 0;
  std::string device;
  // Geometry (absent without a reference).
  std::optional<EmdResult> emd;
  std::string geometry_reference;           // "gt/map.pcd", "lidar/heldout.pcd" or "lidar/map.pcd"
  bool geometry_reference_trained = false;  // the reference is the map that trained the model (circular)
  std::optional<RegionCoverage> region;     // the observed region (with a reference)
  std::string plane_reference;              // "gt/planes.txt" or "LiDAR plane fits (...)" or ""
  double centre_plane_rms_m = -1, centre_plane_median_m = -1;
  size_t centre_plane_counted = 0;
};

// Renders every held-out view on the device and measures. `images` (optional) receives the views' images.
// Errors (a missing file, a scene without held-out views) are exceptions naming the problem.
ModelEvaluation evaluate_model(const std::filesystem::path& model_ply, const std::filesystem::path& scene_dir,
                               const EvalOptions& options, std::vector<ViewImages>* images = nullptr);

nlohmann::json to_json(const ModelEvaluation& e);

// The statement the output and the docs make about LPIPS.
inline constexpr const char* kLpipsNote =
    "not available: LPIPS needs pretrained network weights that this project cannot obtain";

}  // namespace litgs::host
