// The fixed-budget MCMC strategy (Kheradmand et al., "3D Gaussian Splatting as Markov Chain Monte Carlo",
// 2024) on the device: bindings, parameters and the report layout shared by C++ and GLSL. The kernels:
//   mcmc_weights        per Gaussian: dead (transparent, non-finite or off its LiDAR plane) or alive; the
//                       sampling weight of the alive ones (opacity, quantized); report counters.
//   mcmc_list_dead      per Gaussian: dead_index[rank] = i (the rank is the scan of the dead flags).
//   mcmc_sample         per target (each dead row, then each new row): a source drawn in proportion to
//                       opacity from the scanned weights; copies[source] += 1.
//   mcmc_update_sources per Gaussian with copies > 0: opacity and scale of every one of its copies+1 copies.
//   mcmc_copy_rows      per target, one attribute buffer: copy the source row, or zero a row (moments).
//   mcmc_noise          per Gaussian, every step: means += gate(opacity) * lr * noise_lr * Sigma * z.
//   mcmc_regularize     per Gaussian, every step: the gradients of the opacity and scale L1 terms.
#ifndef LITGS_KERNELS_MCMC_SHARED_H
#define LITGS_KERNELS_MCMC_SHARED_H

#ifdef __cplusplus
#include <cstdint>
namespace litgs::kernels {
using uint = uint32_t;
#endif

// Sampling weights are opacity x MCMC_WEIGHT_LEVELS, rounded, so that a uint scan is their CDF (sums stay
// below 2^32 up to MCMC_MAX_GAUSSIANS rows). A live Gaussian (opacity >= 0.005) weighs at least 5.
#define MCMC_WEIGHT_LEVELS 1024u
#define MCMC_MAX_GAUSSIANS 4000000u
// Copies of one source are capped here (3DGS-MCMC's n_max).
#define MCMC_MAX_COPIES 51u

// ---- mcmc_weights.comp (push constants: McmcParams) ----
#define WEIGHTS_BINDING_LOG_SCALES 0      // [N][3] (finiteness)
#define WEIGHTS_BINDING_MEANS 1           // [N][3] (finiteness)
#define WEIGHTS_BINDING_QUATS 2           // [N][4] (finiteness)
#define WEIGHTS_BINDING_OPACITY_LOGITS 3  // [N]
#define WEIGHTS_BINDING_PLANE_DISTANCE 4  // [N] metres; read when flags & MCMC_FLAG_PLANE
#define WEIGHTS_BINDING_WEIGHT 5          // [N] uint: 0 for dead rows
#define WEIGHTS_BINDING_DEAD 6            // [N] uint 0/1
#define WEIGHTS_BINDING_REPORT 7          // [MCMC_REPORT_SLOTS] uint (atomic)
#define WEIGHTS_BINDING_COUNT 8

// ---- mcmc_list_dead.comp (push constants: McmcParams) ----
#define LIST_BINDING_DEAD 0        // [N] uint 0/1
#define LIST_BINDING_DEAD_RANK 1   // [N] uint exclusive scan of DEAD
#define LIST_BINDING_DEAD_INDEX 2  // [dead] uint
#define LIST_BINDING_COUNT 3

// ---- mcmc_sample.comp (push constants: McmcParams; targets = dead + added) ----
#define SAMPLE_BINDING_CDF 0         // [N] uint exclusive scan of the weights
#define SAMPLE_BINDING_DEAD_INDEX 1  // [dead]
#define SAMPLE_BINDING_SOURCE 2      // [targets] uint row to copy from
#define SAMPLE_BINDING_TARGET 3      // [targets] uint row to write: dead_index[t], or N + t - dead
#define SAMPLE_BINDING_COPIES 4      // [N] uint += 1 per draw (atomic; zeroed before)
#define SAMPLE_BINDING_COUNT 5

// ---- mcmc_update_sources.comp (push constants: McmcParams) ----
#define UPDATE_BINDING_COPIES 0          // [N]
#define UPDATE_BINDING_OPACITY_LOGITS 1  // [N] updated in place
#define UPDATE_BINDING_LOG_SCALES 2      // [N][3] updated in place
#define UPDATE_BINDING_COUNT 3

// ---- mcmc_copy_rows.comp (push constants: CopyRowsParams) ----
#define COPY_BINDING_SOURCE 0  // [targets]
#define COPY_BINDING_TARGET 1  // [targets]
#define COPY_BINDING_ROWS 2    // [rows][stride] 32-bit words, updated in place
#define COPY_BINDING_COUNT 3
#define COPY_MODE_SOURCE_TO_TARGET 0u  // rows[target[t]] = rows[source[t]]
#define COPY_MODE_ZERO_TARGET 1u       // rows[target[t]] = 0
#define COPY_MODE_ZERO_SOURCE 2u       // rows[source[t]] = 0 (a relocated source's moments restart)

// ---- mcmc_noise.comp (push constants: McmcParams) ----
#define NOISE_BINDING_MEANS 0           // [N][3] updated in place
#define NOISE_BINDING_LOG_SCALES 1      // [N][3]
#define NOISE_BINDING_QUATS 2           // [N][4]
#define NOISE_BINDING_OPACITY_LOGITS 3  // [N]
#define NOISE_BINDING_COUNT 4

// ---- mcmc_regularize.comp (push constants: McmcParams) ----
#define REG_BINDING_OPACITY_LOGITS 0   // [N]
#define REG_BINDING_LOG_SCALES 1       // [N][3]
#define REG_BINDING_GRAD_OPACITY 2     // [N] += opacity_reg / N * o (1 - o)
#define REG_BINDING_GRAD_LOG_SCALES 3  // [N][3] += scale_reg / (3N) * exp(log_scale)
#define REG_BINDING_COUNT 4

// Flags of McmcParams.flags.
#define MCMC_FLAG_PLANE 1u  // a Gaussian farther than max_plane_distance from its LiDAR plane is dead

// Report counters (one download per relocation, with the dead count and the total weight).
#define MCMC_REPORT_DEAD_NONFINITE 0  // dead rows by the first reason that applies, in this order
#define MCMC_REPORT_DEAD_TRANSPARENT 1
#define MCMC_REPORT_DEAD_PLANE 2
#define MCMC_REPORT_LAST_DEAD_RANK 3  // copied: dead_rank[N-1]; + dead[N-1] = dead rows
#define MCMC_REPORT_LAST_DEAD 4
#define MCMC_REPORT_LAST_CDF 5  // copied: cdf[N-1]; + weight[N-1] = total weight
#define MCMC_REPORT_LAST_WEIGHT 6
#define MCMC_REPORT_SLOTS 8

struct McmcParams {
  uint count;         // N (rows in use)
  uint dead;          // sample: dead rows (targets t < dead overwrite dead_index[t])
  uint targets;       // sample: dead + added rows
  uint total_weight;  // sample: the sum of the weights (> 0)
  uint flags;         // MCMC_FLAG_*
  uint seed;          // sampling and noise: hash(seed, step, index)
  uint step;
  float min_opacity_logit;   // dead below this
  float max_plane_distance;  // dead beyond this (metres; NaN never)
  float min_opacity;         // relocated opacities are clamped to [min_opacity, 1 - 2^-23]
  float noise_scale;         // noise: lr_means x noise_lr
  float opacity_reg;         // regularize: opacity_reg / N
  float scale_reg;           // regularize: scale_reg / (3 N)
  uint reserved0, reserved1, reserved2;
};

struct CopyRowsParams {
  uint targets;
  uint stride;  // 32-bit words per row
  uint mode;    // COPY_MODE_*
  uint reserved;
};

#ifdef __cplusplus
static_assert(sizeof(McmcParams) <= 128);
static_assert(sizeof(CopyRowsParams) <= 128);
static_assert(WEIGHTS_BINDING_COUNT == WEIGHTS_BINDING_REPORT + 1);
static_assert(LIST_BINDING_COUNT == LIST_BINDING_DEAD_INDEX + 1);
static_assert(SAMPLE_BINDING_COUNT == SAMPLE_BINDING_COPIES + 1);
static_assert(UPDATE_BINDING_COUNT == UPDATE_BINDING_LOG_SCALES + 1);
static_assert(COPY_BINDING_COUNT == COPY_BINDING_ROWS + 1);
static_assert(NOISE_BINDING_COUNT == NOISE_BINDING_OPACITY_LOGITS + 1);
static_assert(REG_BINDING_COUNT == REG_BINDING_GRAD_LOG_SCALES + 1);
}  // namespace litgs::kernels
#endif
#endif
