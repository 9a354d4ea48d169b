// Every option of a training run, with the 3DGS defaults where they apply and train_defaults.h where `train`
// and `run` share them; the CLI maps onto it field by field.
#pragma once

#include <algorithm>
#include <cstdint>
#include <string>

#include "host/train/train_defaults.h"
#include "kernels/mcmc/mcmc.h"

namespace litgs::host {

// `--max-gaussians grow` (MCMC): the budget grown inside one training while validation says it pays
// (host/train/budget_growth.h). Phases of `phase_refinements` refinements; at each phase's end, once the
// model fills its budget, the validation views (every `validation_every`-th training view, held back from
// training while the budget grows) are scored, and the budget is multiplied by `factor` while the paired
// per-view PSNR gain over the last measurement is above `min_gain_db` (the mean decides; with
// `noise_multiple` > 0 also that many standard errors, and with `min_transfer` > 0 at least that share of the
// gain of as many training views over the same phase: docs/cli/train.md says why both are off). With
// `roll_back`, a doubling that did not pay is undone: the model returns to the last budget that did, keeping
// its most opaque Gaussians (early stopping that restores the best, applied to the size).
struct BudgetGrowthOptions {
  bool enabled = false;
  // The first budget (raised to the initialization's size where larger): a floor, so that a sparse
  // initialization (a front end's few thousand points) does not spend its doublings below any budget measured
  // best on a real or synthetic scene (docs/budget.md).
  uint32_t start = train_defaults::kGrowthStart;
  double factor = 2.0;
  uint32_t phase_refinements = 3;
  // Decisions end by this share of the iterations, so that the model trains its last stretch at its final
  // size on every training view (the validation views rejoin when it stops).
  double until_fraction = 0.6;
  uint32_t validation_every = 8;
  double min_gain_db = 0.05;
  double noise_multiple = 0.0;
  double min_transfer = 0.0;
  bool roll_back = true;
  // At the decisions' window's end, a growth that still gained takes one more doubling, unjudged, when the
  // next gain extrapolated from the last two is above min_gain_db.
  bool last_doubling = true;
  void check() const;  // throws std::invalid_argument naming the bad field
};

struct TrainOptions {
  uint32_t iterations = train_defaults::kIterations;
  double lambda_geo = train_defaults::kLambdaGeo;  // 0: photometric only
  double lambda_ssim = 0.2;                        // L_pho = (1 - lambda_ssim) L1 + lambda_ssim (1 - SSIM)
  // Scale s of the Cauchy kernel on the point-to-plane residual (kernels/loss/geometric_loss.h), metres; 0:
  // the plain square. Residuals well below s are squared as the method states; the ~1% of LiDAR targets that
  // are not the surface a pixel sees (up to ~1 m off on the synthetic facade, yet half the squared loss's
  // pull on a true render: tests/train/test_plane_targets_synthetic.cc) pull with a bounded force.
  double geo_robust_scale_m = 0.05;
  // false: the LiDAR term's gradient moves Gaussians but leaves their opacity to the image
  // (kernels::RasterizerOptions::depth_gradient_to_opacity).
  bool geo_gradient_to_opacity = true;
  uint32_t sh_degree = 3;  // final SH degree; the active degree rises by one every sh_degree_every
  uint32_t sh_degree_every = 1000;
  // Adaptive density control (3DGS defaults, in iterations).
  uint32_t densify_from = 500;
  uint32_t densify_until = 15000;  // clipped to the run
  uint32_t densify_every = 100;
  uint32_t opacity_reset_every = 3000;
  // Of the averaged screen-space mean gradient of the total loss, in 3DGS units. Not scaled by
  // photometric_weight(): the geometric term's gradient lands in the same statistic, and on the synthetic
  // facade (lambda_geo 0.6, true poses) scaling it by 0.4 densified where depth, not appearance, was off,
  // and lost held-out PSNR (commit a08255b; the figure was not recorded).
  float densify_grad_threshold = 0.0002f;
  // The geometric outlier prune: Gaussians farther from their LiDAR plane than median + k 1.4826 MAD of all
  // such distances (at least 10 cm) are pruned at each refinement; 0 turns it off.
  double plane_prune_k = 5.0;
  uint32_t max_gaussians = 2000000;  // cap of the model size (the budget of the MCMC strategy)
  BudgetGrowthOptions growth;        // enabled: max_gaussians is the ceiling the growth may reach
  // Densification strategy: "adc" (3DGS adaptive density control: clone, split, prune, opacity resets) or
  // "mcmc" (3DGS-MCMC: a fixed budget, relocation of dead Gaussians, position noise, regularizers; the same
  // window and cadence).
  std::string strategy = train_defaults::kStrategy;
  float mcmc_growth = static_cast<float>(train_defaults::kMcmcGrowth);
  float mcmc_noise_lr = 5e5f;  // MCMC: position noise, times the means' learning rate
  float mcmc_opacity_reg =
      0.01f;  // MCMC: L1 weights, relative to the photometric loss (photometric_weight())
  float mcmc_scale_reg = 0.01f;
  float lr_scale = 1.0f;  // multiplies every learning rate (stability tests, tuning)
  // The radiometric level model (host/train/level_plan.h, kernels/level/): "none", "affine" (a gain and an
  // offset per training frame) or "affine-vignetting" (and a vignetting shared by all frames), applied to the
  // render before the photometric loss. Adam rates (decaying log-linearly to a tenth over the run), and the
  // regularizers' weights toward identity and toward smoothness in time, relative to the photometric loss.
  std::string level_model = "none";
  float level_lr_log_gain = 0.02f;
  float level_lr_offset = 0.02f;
  float level_lr_vignetting = 0.002f;
  float level_lambda_identity = 1e-3f;
  float level_lambda_smooth = 1e-2f;
  // Evaluation, checkpoints, reproducibility.
  uint32_t eval_every = 0;        // 0: only at the end
  uint32_t checkpoint_every = 0;  // 0: none
  bool resume = false;            // continue from the newest checkpoint in the output directory
  bool deterministic = false;     // bit-identical gradients (slower)
  uint32_t seed = 0;              // view order and densification noise
  uint32_t progress_every = 50;   // log cadence when stdout is not a terminal
  // point_cloud.ply in the scene's recentred frame (scene = original - world_offset_m, docs/scene-format.md)
  // instead of the original world frame. Training and checkpoints always use the scene frame.
  bool recentred_output = false;
  void check() const;  // throws std::invalid_argument naming the bad field
  // The SH degree rendered after `iterations_done` iterations (the ramp: one more every sh_degree_every).
  uint32_t active_sh_degree(uint32_t iterations_done) const {
    return std::min(sh_degree, iterations_done / sh_degree_every);
  }
  // Refinement and opacity resets run while step < refine_until() (3DGS), so never on the last iteration:
  // Gaussians split, relocated or made transparent there would reach the output unfitted.
  uint32_t refine_until() const { return std::min(densify_until, iterations); }
  kernels::McmcOptions mcmc_options() const;
  // The photometric loss's weight in L, 1 - lambda_geo (1 when lambda_geo = 1: no photometric term to be
  // relative to). 3DGS-MCMC's regularizers, calibrated against a photometric loss at unit weight, are scaled
  // by it: Adam does not see the loss's scale, but their pull relative to the photometric term does, and
  // would otherwise rise 2.5-fold at lambda_geo = 0.6.
  double photometric_weight() const { return lambda_geo < 1.0 ? 1.0 - lambda_geo : 1.0; }
};

}  // namespace litgs::host
