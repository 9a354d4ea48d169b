// Adam for Gaussian splatting: the options (3DGS default learning rates, documented here and nowhere else),
// the per-step learning rates, and the element-wise kernel that applies one step to one parameter buffer.
#pragma once

#include <cstdint>
#include <memory>

#include "engine/buffer.h"
#include "engine/context.h"
#include "engine/kernel.h"
#include "engine/sequence.h"
#include "kernels/optim/optim_shared.h"

namespace litgs::kernels {

// Learning rates of one step, per parameter group.
struct LearningRates {
  float means = 0;  // world units per step (already scaled by the scene extent)
  float log_scales = 0;
  float quats = 0;
  float opacity_logits = 0;
  float sh_dc = 0;    // the first C values of each Gaussian's SH row (degree 0)
  float sh_rest = 0;  // the other (K - 1) * C values
};

// Adam and the 3DGS learning-rate schedule (gaussian-splatting/arguments/__init__.py, OptimizationParams).
struct AdamOptions {
  float beta1 = 0.9f;    // first-moment decay (torch default)
  float beta2 = 0.999f;  // second-moment decay (torch default)
  float eps = 1e-15f;    // added to sqrt(v_hat), as 3DGS sets it
  // Means: get_expon_lr_func(lr_init = means_lr_init * extent, lr_final = means_lr_final * extent,
  // lr_delay_steps, lr_delay_mult, max_steps): log-linear from init to final over max_steps, then final.
  float means_lr_init = 1.6e-4f;       // x scene extent (3DGS position_lr_init)
  float means_lr_final = 1.6e-6f;      // x scene extent (3DGS position_lr_final)
  uint32_t means_lr_delay_steps = 0;   // 3DGS default 0: no delay
  float means_lr_delay_mult = 0.01f;   // 3DGS position_lr_delay_mult; only used when delay_steps > 0
  float sh_dc_lr = 2.5e-3f;            // 3DGS feature_lr
  float sh_rest_lr = 2.5e-3f / 20.0f;  // 3DGS feature_lr / 20
  // 3DGS used 0.05 until 2024 and 0.025 since (with its depth-regularization update); we take 0.025, the
  // current reference default, which is also gentler on the low-contrast thermal images.
  float opacity_lr = 0.025f;
  float log_scales_lr = 5e-3f;  // 3DGS scaling_lr
  float quats_lr = 1e-3f;       // 3DGS rotation_lr

  // Throws std::invalid_argument naming the bad field.
  void check() const;
  // The means' rate at `step` (0-based) of a run of `max_steps`, for a scene of radius `extent`.
  float means_lr(uint32_t step, uint32_t max_steps, float extent) const;
  // All groups' rates at `step`.
  LearningRates rates(uint32_t step, uint32_t max_steps, float extent) const;
};

// The kernel: one Adam step of one buffer. Steps count from 1 (torch's `state['step']` after increment).
class AdamKernel {
 public:
  explicit AdamKernel(engine::Context& context);
  ~AdamKernel();

  struct Target {
    const engine::Buffer* params;      // [count] updated in place
    const engine::Buffer* grads;       // [count]
    const engine::Buffer* exp_avg;     // [count] updated in place
    const engine::Buffer* exp_avg_sq;  // [count] updated in place
    const engine::Buffer* counters;    // [ADAM_COUNTER_SLOTS] uint
  };
  // Records the step. Elements j with (j % period) < lead use `lr`, the others `lr_rest`.
  // Throws std::out_of_range naming a buffer smaller than `count` elements.
  void record(engine::Sequence& sequence, const Target& target, uint64_t count, const AdamOptions& options,
              uint32_t step, float lr, uint32_t counter_slot, float lr_rest = 0.0f, uint32_t period = 1,
              uint32_t lead = 1) const;

 private:
  engine::Context* context_;
  std::unique_ptr<engine::Kernel> kernel_;
};

// The push constants of one Adam step (bias corrections of `step`, counted from 1).
AdamParams adam_params(const AdamOptions& options, uint32_t step, float lr, float lr_rest, uint32_t count,
                       uint32_t period, uint32_t lead, uint32_t counter_slot);

// Throws std::out_of_range when `buffer` holds fewer than `count` values of `value_bytes` bytes.
void check_binding(const engine::Buffer& buffer, uint64_t count, uint64_t value_bytes, const char* what);

}  // namespace litgs::kernels
