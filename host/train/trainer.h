// The training loop: which kernels run when. Views sampled without replacement, SH degree ramp,
// densification window and cadence, evaluation, atomic checkpoints and resume, one small readback per
// iteration (the rasterizer's intersection count).
//
// What a resume promises (`resume`: continue from the newest checkpoint in the output directory):
// - The options must be the checkpoint's, but for those host/train/run_options.h lets change (iterations,
//   eval_every, checkpoint_every, progress_every, recentred_output); any other difference is refused with a
//   message that names each option with both values. Checkpoints written before options were stored
//   (format 1) are resumed with a warning, their options unchecked.
// - With `deterministic`, a run interrupted after a checkpoint and resumed with the same options writes the
//   same bits (point_cloud.ply, and metrics.json but for timings) as the run that was never interrupted.
// - With float atomics (the default) the gradient sums' order varies run to run, so a resumed run is another
//   sample of the same training, not the same bits: its held-out PSNR is as close to an uninterrupted run's
//   as two uninterrupted runs are to each other (tests/gpu/test_train_resume.cc bounds it; the figures:
//   docs/training-outputs.md, "Resume").
// - metrics.json of a resumed run carries the evaluations, counters and resumes of the checkpoint's run.
#pragma once

#include <filesystem>
#include <functional>
#include <nlohmann/json.hpp>
#include <optional>
#include <string>
#include <utility>
#include <vector>

#include "engine/context.h"
#include "host/train/level_plan.h"
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
  std::vector<std::pair<std::string, uint64_t>> peak_device_breakdown;  // by buffer name, most first
  EvalResult final_eval;
  std::vector<EvalResult> evals;
  size_t nonfinite_pruned = 0;        // = counters.pruned_nonfinite
  size_t plane_pruned = 0;            // = counters.pruned_plane: pruned for their distance to the LiDAR plane
  TrainingCounters counters;          // over the whole run, resumed runs included
  std::vector<ResumeRecord> resumes;  // every resume of the run, oldest first
  uint32_t start_iteration = 0;       // where this call started (the checkpoint's iteration, or 0)
  std::vector<std::pair<std::string, double>> kernel_ms_per_iteration;  // GPU timestamps, training steps only
  LevelTable levels;                   // every view's level (identity without a level model): levels.json
  uint64_t level_nonfinite_skips = 0;  // level updates skipped for a non-finite value
  nlohmann::json growth;               // `--max-gaussians grow`: BudgetGrowth::to_json(); null otherwise
};

struct TrainProgress {
  uint32_t iteration, total;
  double loss;  // last read back (every few iterations): (1 - lambda_geo) L_pho + lambda_geo L_geo
  double photometric_loss;  // its L_pho
  double geometric_rms_m;   // sqrt(L_geo): the RMS point-to-plane residual over valid pixels (NaN: no term)
  double psnr_db;           // last evaluation (or NaN)
  size_t gaussians;
  double iterations_per_s;
  TrainingCounters counters;  // so far, over the whole run
};

// Trains `initial` (unused when resuming) on `data` and writes `out_dir/point_cloud.ply` (in the original
// world frame, or the scene's with options.recentred_output: host/train/output_frame.h) and
// `out_dir/metrics.json` (atomically). `planes` (optional) drives the geometric loss; without it lambda_geo
// must be 0. `gt_planes` (optional): the scene's true planes, sampled as points with their plane's normal;
// evaluation then also reports the RMSE of the rendered depth's point-to-plane residual against them.
// `notice` receives the resume's notes and warnings, one line each (default: std::cerr).
TrainReport train(engine::Context& context, const TrainingData& data, const kernels::GaussianModel& initial,
                  const PlanarMap* planes, const TrainOptions& options, const std::filesystem::path& out_dir,
                  const std::function<void(const TrainProgress&)>& progress = {},
                  const PlanarMap* gt_planes = nullptr,
                  const std::function<void(const std::string&)>& notice = {});

}  // namespace litgs::host
