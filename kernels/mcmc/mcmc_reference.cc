#include "kernels/mcmc/mcmc_reference.h"

#include <algorithm>
#include <cmath>
#include <stdexcept>

#include "kernels/mcmc/mcmc_math.h"

namespace litgs::kernels {

namespace {

double sigmoid(double x) {
  return 1.0 / (1.0 + std::exp(-x));
}

bool finite_row(const GaussianModel& m, size_t i) {
  for (int k = 0; k < 3; ++k)
    if (!std::isfinite(m.means[3 * i + k]) || !std::isfinite(m.log_scales[3 * i + k])) return false;
  for (int k = 0; k < 4; ++k)
    if (!std::isfinite(m.quats[4 * i + k])) return false;
  return std::isfinite(m.opacity_logits[i]);
}

}  // namespace

double mcmc_normalizer_alternating(double x, uint32_t n) {
  long double sum = 0;
  for (uint32_t i = 1; i <= n; ++i) {
    long double binom = 1;  // C(i-1, k)
    for (uint32_t k = 0; k < i; ++k) {
      const long double term =
          binom * std::pow(static_cast<long double>(x), k + 1) / std::sqrt((long double)(k + 1));
      sum += (k % 2 == 0) ? term : -term;
      binom = binom * (i - 1 - k) / (k + 1);
    }
  }
  return static_cast<double>(sum);
}

double mcmc_normalizer_reference(double x, uint32_t n) {
  return mcmc_math::stacked_opacity_integral(x, n, 0.01, 900u);
}

std::vector<uint32_t> mcmc_dead_reference(const GaussianModel& model, const McmcOptions& options,
                                          const std::vector<float>& plane_distance) {
  const double min_logit = std::log(double{options.min_opacity} / (1.0 - options.min_opacity));
  std::vector<uint32_t> dead;
  for (size_t i = 0; i < model.size(); ++i) {
    const bool off_plane = !plane_distance.empty() && std::isfinite(options.max_plane_distance_m) &&
                           plane_distance[i] > options.max_plane_distance_m;
    if (!finite_row(model, i) || model.opacity_logits[i] < min_logit || off_plane)
      dead.push_back(static_cast<uint32_t>(i));
  }
  return dead;
}

uint32_t mcmc_draw_reference(const std::vector<uint32_t>& cdf, uint32_t total, uint32_t seed, uint32_t step,
                             uint32_t t) {
  using densify_math::pcg_hash;
  const uint32_t h = pcg_hash(pcg_hash(pcg_hash(seed) ^ step) ^ t);
  const uint32_t u = static_cast<uint32_t>((uint64_t{h} * total) >> 32);
  // The largest i with cdf[i] <= u.
  const auto it = std::upper_bound(cdf.begin(), cdf.end(), u);
  return static_cast<uint32_t>(it - cdf.begin()) - 1u;
}

TrainingState mcmc_relocate_reference(const TrainingState& in, const std::vector<uint32_t>& source,
                                      const std::vector<uint32_t>& target, const McmcOptions& options) {
  if (source.size() != target.size()) throw std::invalid_argument("mcmc_relocate_reference: sizes differ");
  TrainingState out = in;
  GaussianModel& m = out.model;
  std::vector<uint32_t> copies(m.size(), 0);
  for (uint32_t s : source) ++copies.at(s);
  for (size_t i = 0; i < m.size(); ++i) {
    if (copies[i] == 0) continue;
    const uint32_t n = std::min(copies[i] + 1u, MCMC_MAX_COPIES);
    const double o = sigmoid(in.model.opacity_logits[i]);
    const double o_new = mcmc_math::relocated_opacity(o, n);
    const double delta = std::log(o / mcmc_normalizer_reference(o_new, n));
    const double clamped = std::clamp(o_new, double{options.min_opacity}, 1.0 - 1.0 / 8388608.0);
    m.opacity_logits[i] = static_cast<float>(std::log(clamped / (1.0 - clamped)));
    for (int k = 0; k < 3; ++k)
      m.log_scales[3 * i + k] = static_cast<float>(in.model.log_scales[3 * i + k] + delta);
  }
  const size_t sv = m.sh.size() / std::max<size_t>(m.size(), 1);
  for (size_t t = 0; t < source.size(); ++t) {
    const size_t s = source[t], d = target[t];
    std::copy_n(&m.means[3 * s], 3, &m.means[3 * d]);
    std::copy_n(&m.log_scales[3 * s], 3, &m.log_scales[3 * d]);
    std::copy_n(&m.quats[4 * s], 4, &m.quats[4 * d]);
    m.opacity_logits[d] = m.opacity_logits[s];
    std::copy_n(&m.sh[sv * s], sv, &m.sh[sv * d]);
    out.grad_accum[d] = 0;
    out.denom[d] = 0;
    out.max_radius[d] = 0;
  }
  for (uint32_t g = 0; g < kParamGroupCount; ++g) {
    const size_t width = out.exp_avg[g].size() / std::max<size_t>(m.size(), 1);
    for (size_t t = 0; t < source.size(); ++t)
      for (size_t row : {size_t{source[t]}, size_t{target[t]}})
        for (size_t k = 0; k < width; ++k)
          out.exp_avg[g][row * width + k] = out.exp_avg_sq[g][row * width + k] = 0;
  }
  return out;
}

std::vector<double> mcmc_noise_reference(const GaussianModel& model, const McmcOptions& options,
                                         float means_lr, uint32_t step) {
  std::vector<double> means(model.means.begin(), model.means.end());
  const double scale = double{means_lr} * options.noise_lr;
  for (size_t i = 0; i < model.size(); ++i) {
    const glm::dvec3 ls(model.log_scales[3 * i], model.log_scales[3 * i + 1], model.log_scales[3 * i + 2]);
    const glm::dvec4 q(model.quats[4 * i], model.quats[4 * i + 1], model.quats[4 * i + 2],
                       model.quats[4 * i + 3]);
    const glm::dvec3 offset = splat_math::covariance_world(ls, q) *
                              mcmc_math::noise_normals(options.seed, step, static_cast<uint32_t>(i)) *
                              (mcmc_math::noise_gate(model.opacity_logits[i]) * scale);
    if (!std::isfinite(offset.x) || !std::isfinite(offset.y) || !std::isfinite(offset.z)) continue;
    for (int k = 0; k < 3; ++k) means[3 * i + k] += offset[k];
  }
  return means;
}

void mcmc_regularization_reference(const GaussianModel& model, const McmcOptions& options,
                                   std::vector<double>& grad_opacity, std::vector<double>& grad_log_scales) {
  const double n = static_cast<double>(model.size());
  grad_opacity.assign(model.size(), 0.0);
  grad_log_scales.assign(3 * model.size(), 0.0);
  for (size_t i = 0; i < model.size(); ++i) {
    const double o = sigmoid(model.opacity_logits[i]);
    grad_opacity[i] = options.opacity_reg / n * o * (1.0 - o);
    for (int k = 0; k < 3; ++k)
      grad_log_scales[3 * i + k] =
          options.scale_reg / (3.0 * n) * std::exp(std::min<double>(model.log_scales[3 * i + k], 20.0));
  }
}

}  // namespace litgs::kernels
