// Adaptive density control between training steps: at refinement steps, densify and prune (ADC) or relocate
// dead Gaussians and grow (MCMC), both with the geometric outlier prune (Gaussians far from their LiDAR
// plane); the ADC opacity resets.
#pragma once

#include <cstdint>
#include <memory>

#include "engine/buffer.h"
#include "engine/context.h"
#include "host/train/lidar_planes.h"
#include "host/train/run_record.h"
#include "host/train/train_options.h"
#include "kernels/densify/densify.h"
#include "kernels/mcmc/mcmc.h"
#include "kernels/optim/trainable_gaussians.h"

namespace litgs::host {

class DensityControl {
 public:
  // `planes` (optional) drives the plane prune when options.lambda_geo > 0 and options.plane_prune_k > 0.
  DensityControl(engine::Context& context, const TrainOptions& options, const PlanarMap* planes,
                 float scene_extent_m);
  ~DensityControl();

  // After the step `step` (1-based): refines if `step` is a refinement step, resets opacities (ADC) if it is
  // a reset step. `mcmc` is the MCMC strategy (null: ADC). May replace model.gaussians(). Adds what it
  // removed to `counters`.
  void after_step(kernels::TrainableGaussians& model, kernels::McmcStrategy* mcmc, uint32_t step,
                  TrainingCounters& counters);
  // The model's cap from now on (a growing budget: host/train/budget_growth.h).
  void set_budget(uint32_t max_gaussians) {
    densify_.max_gaussians = max_gaussians;
    mcmc_.max_gaussians = max_gaussians;
  }
  // MCMC's rows added per refinement from now on, as a fraction of the model (a growing budget fills each
  // doubling within its phase).
  void set_mcmc_growth(float growth) { mcmc_.growth = growth; }

 private:
  engine::Context* context_;
  const TrainOptions* options_;
  float extent_;
  kernels::DensifyOptions densify_;
  kernels::McmcOptions mcmc_;
  std::unique_ptr<PlaneDistance> plane_index_;
  std::unique_ptr<engine::DeviceArray<float>> plane_distances_;
};

}  // namespace litgs::host
