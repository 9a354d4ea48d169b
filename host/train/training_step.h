// One training iteration on the device: render a view (the rasterizer's one readback, the intersection
// count), the photometric and geometric losses and their gradients, the backward, the densification
// statistics (ADC) or the regularizers (MCMC), the Adam step and the MCMC position noise: one submit.
#pragma once

#include <cstdint>
#include <map>
#include <memory>
#include <string>
#include <vector>

#include "engine/buffer.h"
#include "engine/context.h"
#include "host/train/lidar_planes.h"
#include "host/train/run_record.h"
#include "host/train/train_options.h"
#include "host/train/training_data.h"
#include "kernels/level/level_model.h"
#include "kernels/loss/geometric_loss.h"
#include "kernels/loss/photometric_loss.h"
#include "kernels/mcmc/mcmc.h"
#include "kernels/optim/trainable_gaussians.h"
#include "kernels/splat/rasterizer.h"

namespace litgs::host {

// GPU time per kernel, summed over a run (timestamps).
using KernelTimes = std::map<std::string, double>;

// The loss of the last step, read from a host-visible buffer (no sync).
struct StepLosses {
  double total;            // (1 - lambda_geo) L_pho + lambda_geo L_geo
  double photometric;      // L_pho
  double geometric_rms_m;  // sqrt(L_geo), NaN without the geometric term
};

class TrainingStep {
 public:
  // `planes` (required when options.lambda_geo > 0) gives each training view its LiDAR targets. Uploads
  // every view's target image (and LiDAR maps) once.
  TrainingStep(engine::Context& context, const TrainingData& data, const PlanarMap* planes,
               const TrainOptions& options, kernels::Rasterizer& rasterizer);
  ~TrainingStep();

  // Iteration `it` (0-based) on training view `view`: one forward, one submit. `mcmc` is the MCMC strategy
  // (null: ADC). `level` (null: none, and nothing of it is recorded) levels the render before the
  // photometric loss and takes `level_step` (its frame is the view's index). GPU times are added to `times`,
  // and the render's culls and walks cut short to `counters` (copied to host-visible memory inside the
  // step's submit: no extra sync).
  void run(kernels::TrainableGaussians& model, kernels::McmcStrategy* mcmc, kernels::LevelModel* level,
           const kernels::LevelStep& level_step, uint32_t it, uint32_t view, KernelTimes& times,
           TrainingCounters& counters);
  StepLosses last_losses() const;

 private:
  struct ViewBuffers;
  engine::Context* context_;
  const TrainingData* data_;
  const TrainOptions* options_;
  kernels::Rasterizer* rasterizer_;
  kernels::McmcOptions mcmc_options_;
  kernels::PhotometricLoss photometric_;
  kernels::GeometricLoss geometric_;
  engine::DeviceArray<float> losses_;              // [kLossSlots], host-visible
  engine::DeviceArray<uint32_t> render_counters_;  // [SPLAT_COUNTER_COUNT] the rasterizer's, host-visible
  uint64_t walks_cut_seen_ = 0;  // the rasterizer's running total of walks cut short at the last step
  std::vector<ViewBuffers> views_;
};

}  // namespace litgs::host
