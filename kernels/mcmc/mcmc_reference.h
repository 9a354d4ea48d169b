// The CPU reference of the MCMC strategy, in double: the relocation normalizer in the paper's own form
// (alternating binomial sums, for checking the quadrature where that form is still accurate), the dead rows,
// the draws, the relocation of a model given the draws, the noise and the regularizers' gradients.
#pragma once

#include <cstdint>
#include <vector>

#include "kernels/mcmc/mcmc.h"
#include "kernels/optim/training_state.h"

namespace litgs::kernels {

// 3DGS-MCMC eq. 9's normalizer sum_{i=1..n} sum_{k=0..i-1} C(i-1,k) (-1)^k x^(k+1) / sqrt(k+1), summed in
// long double exactly as written. Accurate only for small n (it cancels catastrophically as n grows).
double mcmc_normalizer_alternating(double x, uint32_t n);
// The same quantity by the positive integral of mcmc_math.h on a fine grid (step 0.01 to s = 9), in double.
double mcmc_normalizer_reference(double x, uint32_t n);

// Rows that are dead under `options` (index order); `plane_distance` may be empty.
std::vector<uint32_t> mcmc_dead_reference(const GaussianModel& model, const McmcOptions& options,
                                          const std::vector<float>& plane_distance);
// Draw t's source given the exclusive scan `cdf` of the weights and their `total` (the kernel's integer
// arithmetic, so the same draw exactly).
uint32_t mcmc_draw_reference(const std::vector<uint32_t>& cdf, uint32_t total, uint32_t seed, uint32_t step,
                             uint32_t t);
// The state after relocating: for each draw t, row target[t] becomes a copy of row source[t] after the
// sources' opacity and scale updates; moments of targets and sources restart; statistics of targets are zero.
// `in` must already hold every target row (added rows zero).
TrainingState mcmc_relocate_reference(const TrainingState& in, const std::vector<uint32_t>& source,
                                      const std::vector<uint32_t>& target, const McmcOptions& options);
// Means after one noise step.
std::vector<double> mcmc_noise_reference(const GaussianModel& model, const McmcOptions& options,
                                         float means_lr, uint32_t step);
// The regularizers' gradients w.r.t. the opacity logits ([N]) and log-scales ([N][3]).
void mcmc_regularization_reference(const GaussianModel& model, const McmcOptions& options,
                                   std::vector<double>& grad_opacity, std::vector<double>& grad_log_scales);

}  // namespace litgs::kernels
