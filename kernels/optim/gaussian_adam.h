// The fused training update (kernels/optim/gaussian_adam.comp): the projection's backward, 3DGS-MCMC's
// regularizers and Adam for every parameter group in one dispatch, from the rasterizer's per-Gaussian rows,
// so that training stores no parameter gradient. Element for element the arithmetic of project_backward,
// mcmc_regularize and adam run one after the other.
#pragma once

#include <array>
#include <cstdint>
#include <memory>

#include "engine/buffer.h"
#include "engine/context.h"
#include "engine/kernel.h"
#include "engine/sequence.h"
#include "kernels/optim/adam.h"
#include "kernels/splat/splat_types.h"

namespace litgs::kernels {

// The regularizers' gradient weights of one step (McmcStrategy::regularization_weights): opacity_reg * o (1
// - o) is added to each opacity logit's gradient, scale_reg * exp(log_scale) to each log-scale's.
struct RegularizationWeights {
  float opacity = 0;
  float scale = 0;
};

class GaussianAdamKernel {
 public:
  // beta1, beta2 and eps of `options` are built into the kernel.
  GaussianAdamKernel(engine::Context& context, uint32_t channels, const AdamOptions& options);
  ~GaussianAdamKernel();

  struct Target {
    // Parameters, first and second moments, in ParamGroup order (means, log_scales, quats, opacity_logits,
    // sh), updated in place.
    std::array<const engine::Buffer*, 5> params{}, exp_avg{}, exp_avg_sq{};
    const engine::Buffer* counters = nullptr;    // [ADAM_COUNTER_SLOTS] uint: slot g counts group g's skips
    const engine::Buffer* tile_rects = nullptr;  // [N][2], the forward's
    const engine::Buffer* grad2d = nullptr;      // [N][SPLAT_GRAD2D_FIXED + C], the backward's
  };
  // Records one step (counted from 1) for `gaussians` Gaussians of `sh_coeffs` coefficients seen from
  // `camera`. Throws std::invalid_argument for options other than the kernel's or a bad step or degree, and
  // std::out_of_range naming a buffer that is too small.
  void record(engine::Sequence& sequence, const Target& target, uint32_t gaussians, uint32_t sh_coeffs,
              const SplatCamera& camera, const AdamOptions& options, uint32_t step, const LearningRates& lr,
              const RegularizationWeights& regularization) const;

 private:
  engine::Context* context_;
  uint32_t channels_;
  AdamOptions options_;
  std::unique_ptr<engine::Kernel> kernel_;
};

}  // namespace litgs::kernels
