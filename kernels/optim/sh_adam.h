// Adam on the SH coefficients with their gradient computed in the kernel (kernels/optim/sh_adam.comp) from
// the colour gradient of the rasterizer's per-Gaussian rows, so that training stores no SH gradient.
#pragma once

#include <cstdint>
#include <memory>

#include "engine/buffer.h"
#include "engine/context.h"
#include "engine/kernel.h"
#include "engine/sequence.h"
#include "kernels/optim/adam.h"
#include "kernels/splat/splat_types.h"

namespace litgs::kernels {

class ShAdamKernel {
 public:
  ShAdamKernel(engine::Context& context, uint32_t channels);
  ~ShAdamKernel();

  struct Target {
    const engine::Buffer* sh;          // [N][K][C] updated in place
    const engine::Buffer* exp_avg;     // [N][K][C] updated in place
    const engine::Buffer* exp_avg_sq;  // [N][K][C] updated in place
    const engine::Buffer* counters;    // [ADAM_COUNTER_SLOTS] uint
    const engine::Buffer* means;       // [N][3], as the backward read them (record before the means' step)
    const engine::Buffer* tile_rects;  // [N][2], the forward's
    const engine::Buffer* grad2d;      // [N][SPLAT_GRAD2D_FIXED + C], the backward's
  };
  // Records one step for `gaussians` Gaussians of `sh_coeffs` coefficients seen from `camera` (its centre
  // and active SH degree); the DC coefficients use `lr_dc`, the others `lr_rest`. Throws std::out_of_range
  // naming a buffer that is too small.
  void record(engine::Sequence& sequence, const Target& target, uint32_t gaussians, uint32_t sh_coeffs,
              const SplatCamera& camera, const AdamOptions& options, uint32_t step, float lr_dc,
              float lr_rest, uint32_t counter_slot) const;

 private:
  engine::Context* context_;
  uint32_t channels_;
  std::unique_ptr<engine::Kernel> kernel_;
};

}  // namespace litgs::kernels
