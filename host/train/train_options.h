// Every option of a training run, with the 3DGS defaults where they apply; the CLI maps onto it field by
// field.
#pragma once

#include <cstdint>
#include <string>

#include "kernels/mcmc/mcmc.h"

namespace litgs::host {

struct TrainOptions {
  uint32_t iterations = 7000;
  double lambda_geo = 0.6;         // L = (1 - lambda_geo) L_pho + lambda_geo L_geo (0: photometric only)
  double lambda_ssim = 0.2;        // L_pho = (1 - lambda_ssim) L1 + lambda_ssim (1 - SSIM)
  uint32_t sh_degree = 3;          // final SH degree; the active degree rises by one every sh_degree_every
  uint32_t sh_degree_every = 1000;
  // Adaptive density control (3DGS defaults, in iterations).
  uint32_t densify_from = 500;
  uint32_t densify_until = 15000;  // clipped to the run
  uint32_t densify_every = 100;
  uint32_t opacity_reset_every = 3000;
  // Of the averaged screen-space mean gradient, in 3DGS units: for the photometric loss at unit weight. The
  // trainer applies it times photometric_weight(), as the gradients it thresholds carry that factor.
  float densify_grad_threshold = 0.0002f;
  uint32_t max_gaussians = 2000000;        // cap of the model size (the budget of the MCMC strategy)
  // Densification strategy: "adc" (3DGS adaptive density control: clone, split, prune, opacity resets) or
  // "mcmc" (3DGS-MCMC: a fixed budget, relocation of dead Gaussians, position noise, regularizers; the same
  // window and cadence).
  std::string strategy = "adc";
  float mcmc_growth = 0.05f;    // MCMC: rows added per refinement, as a fraction of the model
  float mcmc_noise_lr = 5e5f;   // MCMC: position noise, times the means' learning rate
  float mcmc_opacity_reg = 0.01f;  // MCMC: L1 weights, relative to the photometric loss (photometric_weight())
  float mcmc_scale_reg = 0.01f;
  float lr_scale = 1.0f;                   // multiplies every learning rate (stability tests, tuning)
  // Evaluation, checkpoints, reproducibility.
  uint32_t eval_every = 0;         // 0: only at the end
  uint32_t checkpoint_every = 0;   // 0: none
  bool resume = false;             // continue from the newest checkpoint in the output directory
  bool deterministic = false;      // bit-identical gradients (slower)
  uint32_t seed = 0;               // view order and densification noise
  uint32_t progress_every = 50;    // log cadence when stdout is not a terminal
  void check() const;              // throws std::invalid_argument naming the bad field
  kernels::McmcOptions mcmc_options() const;
  // The photometric loss's weight in L, 1 - lambda_geo (1 when lambda_geo = 1: no photometric term to be
  // relative to). Settings calibrated for photometric-only training (3DGS's gradient threshold, 3DGS-MCMC's
  // regularizers) are scaled by it: Adam does not see the loss's scale, but those do, and the geometric term
  // would otherwise cut densification at lambda_geo = 0.6 and raise the regularizers' pull 2.5-fold.
  double photometric_weight() const { return lambda_geo < 1.0 ? 1.0 - lambda_geo : 1.0; }
};

}  // namespace litgs::host
