// Evaluation of a model on the held-out views: PSNR and SSIM against the targets, and where the scene has
// true planes, the RMSE of the rendered depth's point-to-plane residual against them. Images are scored as
// an image shows them: the render clamped to [0, 1] (shown_as_written).
#pragma once

#include <cstdint>
#include <span>
#include <vector>

#include "host/train/level_plan.h"
#include "host/train/lidar_planes.h"
#include "host/train/run_record.h"
#include "host/train/train_options.h"
#include "host/train/training_data.h"
#include "kernels/splat/rasterizer.h"

namespace litgs::host {

// The rendered depth's point-to-plane residuals against true planes in one view (camera frame), over the
// pixels where a true plane is seen and the render's alpha is at least 0.5: their sum of squares and count.
struct PlaneResidualSum {
  double sum_sq_m2 = 0;
  size_t count = 0;
};
PlaneResidualSum depth_plane_residuals(const PlanarMap& truth_map, const kernels::SplatCamera& camera,
                                       std::span<const float> depth, std::span<const float> alpha);

// The render as `render` writes it, before quantization: every value clamped to [0, 1].
std::vector<float> shown_as_written(std::span<const float> render);

class Evaluator {
 public:
  // `gt_planes` (optional): the scene's true planes, sampled as points with their plane's normal.
  Evaluator(const TrainingData& data, const TrainOptions& options, const PlanarMap* gt_planes,
            kernels::Rasterizer& rasterizer);

  // The held-out views' mean PSNR, SSIM and mean absolute error in counts (zero without held-out views)
  // after `iteration` iterations (the SH degree of that point of the ramp). `levels` (optional, a level
  // model's table): each held-out render is scored at its interpolated level, and at identity beside it.
  // `renders` (optional) receives each held-out view's render (before any level), in the order of views().
  EvalResult evaluate(const kernels::DeviceGaussians& gaussians, uint32_t iteration,
                      std::vector<kernels::RenderImages<float>>* renders = nullptr,
                      const LevelTable* levels = nullptr);
  const std::vector<uint32_t>& views() const { return views_; }

 private:
  const TrainingData* data_;
  const TrainOptions* options_;
  const PlanarMap* gt_planes_;
  kernels::Rasterizer* rasterizer_;
  std::vector<uint32_t> views_;  // indices of the held-out views
};

}  // namespace litgs::host
