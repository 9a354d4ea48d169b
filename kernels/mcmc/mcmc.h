// The fixed-budget MCMC densification strategy (3DGS-MCMC, Kheradmand et al. 2024), an alternative to
// 3DGS's adaptive density control: the model never exceeds `max_gaussians`. Dead Gaussians (nearly
// transparent, non-finite, or off their LiDAR plane) are relocated onto live ones drawn in proportion to
// opacity, with opacity and scale chosen so the stacked copies render like the original; the model grows by
// `growth` per refinement up to the cap the same way; every step adds covariance-shaped noise to nearly
// transparent Gaussians and L1 penalties on opacity and scale. Everything runs on the device; a relocation
// reads back 32 bytes.
#pragma once

#include <cstdint>
#include <limits>
#include <memory>
#include <string>
#include <vector>

#include "engine/buffer.h"
#include "engine/context.h"
#include "engine/kernel.h"
#include "engine/sequence.h"
#include "kernels/mcmc/mcmc_shared.h"
#include "kernels/optim/trainable_gaussians.h"
#include "kernels/scan/scan.h"
#include "kernels/splat/rasterizer.h"

namespace litgs::kernels {

// Defaults are the reference implementation's (gsplat MCMCStrategy and its trainer's regularizers).
struct McmcOptions {
  uint32_t max_gaussians = 1000000;  // the budget (cap_max); at most MCMC_MAX_GAUSSIANS
  float growth = 0.05f;              // rows added per refinement: min(cap, (1 + growth) N) - N
  float min_opacity = 0.005f;        // dead below this opacity
  float noise_lr = 5e5f;             // noise scale, times the means' learning rate
  float opacity_reg = 0.01f;         // loss += opacity_reg * mean(opacity)
  float scale_reg = 0.01f;           // loss += scale_reg * mean(exp(log_scale))
  // Dead where the caller's per-Gaussian plane distance exceeds this (metres); infinity: off.
  float max_plane_distance_m = std::numeric_limits<float>::infinity();
  uint32_t seed = 0;  // sampling and noise depend only on (seed, step, index)

  // Throws std::invalid_argument naming the bad field.
  void check() const;
};

struct McmcReport {
  uint32_t before = 0;
  uint32_t dead_nonfinite = 0;  // dead rows by the first reason that applies
  uint32_t dead_transparent = 0;
  uint32_t dead_plane = 0;
  uint32_t relocated = 0;  // dead rows overwritten (all of them, unless nothing is alive)
  uint32_t added = 0;      // rows added
  uint32_t after = 0;
  uint32_t dead() const { return dead_nonfinite + dead_transparent + dead_plane; }
  std::string to_string() const;
};

class McmcStrategy {
 public:
  explicit McmcStrategy(engine::Context& context);
  ~McmcStrategy();
  McmcStrategy(const McmcStrategy&) = delete;
  McmcStrategy& operator=(const McmcStrategy&) = delete;

  // Relocates the dead rows and adds rows up to the budget (two submits, one 32-byte readback). A
  // relocated or added row and its source restart their Adam moments; statistics of new rows are zero.
  // `plane_distance` ([N] float metres) enables the plane criterion of the options. Call
  // Rasterizer::forward again after it.
  McmcReport relocate_and_grow(TrainableGaussians& model, const McmcOptions& options, uint32_t step,
                               const engine::Buffer* plane_distance = nullptr);
  // The regularizers' gradient weights for `gaussians` rows: opacity_reg / N and scale_reg / (3 N) (the
  // losses are means over the rows), for the fused step (TrainableGaussians::FusedStep).
  static RegularizationWeights regularization_weights(const McmcOptions& options, uint32_t gaussians);
  // Records the regularizers' gradients into stored `grads` (after the backward, before the Adam step).
  void record_regularization(engine::Sequence& sequence, const TrainableGaussians& model,
                             const Rasterizer::DeviceGrads& grads, const McmcOptions& options) const;
  // Records the position noise (after the Adam step); `means_lr` is the step's learning rate of the means.
  void record_noise(engine::Sequence& sequence, const TrainableGaussians& model, const McmcOptions& options,
                    float means_lr, uint32_t step) const;
  // The last relocation's draws: row target[t] became a copy of row source[t] (tests and diagnostics).
  struct Draws {
    std::vector<uint32_t> source, target;
  };
  Draws last_draws() const;

 private:
  engine::Context* context_;
  ExclusiveScan scan_;
  std::unique_ptr<engine::Kernel> weights_, list_dead_, sample_, update_sources_, copy_rows_, noise_,
      regularize_;
  // Scratch, grown geometrically: [N] weight, cdf, dead, dead rank, copies; [targets] dead index, source,
  // target; the report.
  std::unique_ptr<engine::DeviceArray<uint32_t>> weight_, cdf_, dead_, dead_rank_, copies_, dead_index_,
      source_, target_, report_;
  std::unique_ptr<engine::DeviceArray<float>> no_plane_;
  uint32_t last_targets_ = 0;
};

}  // namespace litgs::kernels
