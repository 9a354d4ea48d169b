// The training loop: which kernels run when. Views sampled without replacement, SH degree ramp,
// densification window and cadence, evaluation, atomic checkpoints and exact resume, one small readback
// per iteration (the rasterizer's intersection count).
#pragma once

#include <filesystem>
#include <functional>
#include <optional>
#include <string>
#include <utility>
#include <vector>

#include "engine/context.h"
#include "host/train/lidar_planes.h"
#include "host/train/run_record.h"
#include "host/train/train_options.h"
#include "host/train/training_data.h"
#include "kernels/splat/splat_types.h"

namespace litgs::host {

struct TrainReport {
  uint32_t iterations = 0;
  double wall_s = 0;
  double ms_per_iteration = 0;
  size_t gaussians = 0;
  uint64_t peak_device_bytes = 0;
  EvalResult final_eval;
  std::vector<EvalResult> evals;
  size_t nonfinite_pruned = 0;
  size_t plane_pruned = 0;  // Gaussians pruned for their distance to the LiDAR plane
  std::vector<std::pair<std::string, double>> kernel_ms_per_iteration;  // GPU timestamps, training steps only
};

struct TrainProgress {
  uint32_t iteration, total;
  double loss;      // last read back (every few iterations): (1 - lambda_geo) L_pho + lambda_geo L_geo
  double photometric_loss;  // its L_pho
  double geometric_rms_m;   // sqrt(L_geo): the RMS point-to-plane residual over valid pixels (NaN: no term)
  double psnr_db;   // last evaluation (or NaN)
  size_t gaussians;
  double iterations_per_s;
};

// Trains `initial` on `data` and writes `out_dir/point_cloud.ply` and `out_dir/metrics.json` (atomically).
// `planes` (optional) drives the geometric loss; without it lambda_geo must be 0.
// `gt_planes` (optional): the scene's true planes, sampled as points with their plane's normal; evaluation
// then also reports the RMSE of the rendered depth's point-to-plane residual against them.
TrainReport train(engine::Context& context, const TrainingData& data, const kernels::GaussianModel& initial,
                  const PlanarMap* planes, const TrainOptions& options, const std::filesystem::path& out_dir,
                  const std::function<void(const TrainProgress&)>& progress = {},
                  const PlanarMap* gt_planes = nullptr);

}  // namespace litgs::host
