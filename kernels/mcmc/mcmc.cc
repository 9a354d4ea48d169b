#include "kernels/mcmc/mcmc.h"

#include <algorithm>
#include <cmath>
#include <stdexcept>
#include <vector>

#include "kernels/device_growth.h"
#include "kernels/elementwise.h"
#include "kernels/optim/adam.h"
#include "kernels/subgroup_kernel.h"

namespace litgs::kernels {

using engine::Access;
using engine::DeviceArray;

namespace {

void require(bool ok, const char* field, double value, const char* rule) {
  if (!ok)
    throw std::invalid_argument(std::string("McmcOptions.") + field + " = " + std::to_string(value) + ": " +
                                rule);
}

float logit(double p) {
  return static_cast<float>(std::log(p / (1.0 - p)));
}

}  // namespace

void McmcOptions::check() const {
  require(max_gaussians > 0 && max_gaussians <= MCMC_MAX_GAUSSIANS, "max_gaussians", max_gaussians,
          "must be in [1, 4000000] (the uint CDF of the sampling weights)");
  require(growth >= 0 && std::isfinite(growth), "growth", growth, "must be finite and >= 0");
  require(min_opacity > 0 && min_opacity < 1, "min_opacity", min_opacity, "must be in (0, 1)");
  require(noise_lr >= 0 && std::isfinite(noise_lr), "noise_lr", noise_lr, "must be finite and >= 0");
  require(opacity_reg >= 0 && std::isfinite(opacity_reg), "opacity_reg", opacity_reg,
          "must be finite and >= 0");
  require(scale_reg >= 0 && std::isfinite(scale_reg), "scale_reg", scale_reg, "must be finite and >= 0");
  require(!std::isnan(max_plane_distance_m) && max_plane_distance_m >= 0, "max_plane_distance_m",
          max_plane_distance_m, "must be >= 0 (infinity: off)");
}

std::string McmcReport::to_string() const {
  return std::to_string(before) + " -> " + std::to_string(after) + " Gaussians: " + std::to_string(dead()) +
         " dead (" + std::to_string(dead_transparent) + " transparent, " + std::to_string(dead_nonfinite) +
         " non-finite, " + std::to_string(dead_plane) + " off-plane), " + std::to_string(relocated) +
         " relocated, " + std::to_string(added) + " added";
}

McmcStrategy::McmcStrategy(engine::Context& context) : context_(&context), scan_(context) {
  weights_ = make_kernel(context, "mcmc/mcmc_weights", WEIGHTS_BINDING_COUNT, sizeof(McmcParams));
  list_dead_ = make_kernel(context, "mcmc/mcmc_list_dead", LIST_BINDING_COUNT, sizeof(McmcParams));
  sample_ = make_kernel(context, "mcmc/mcmc_sample", SAMPLE_BINDING_COUNT, sizeof(McmcParams));
  update_sources_ =
      make_kernel(context, "mcmc/mcmc_update_sources", UPDATE_BINDING_COUNT, sizeof(McmcParams));
  copy_rows_ = make_kernel(context, "mcmc/mcmc_copy_rows", COPY_BINDING_COUNT, sizeof(CopyRowsParams));
  noise_ = make_kernel(context, "mcmc/mcmc_noise", NOISE_BINDING_COUNT, sizeof(McmcParams));
  regularize_ = make_kernel(context, "mcmc/mcmc_regularize", REG_BINDING_COUNT, sizeof(McmcParams));
  report_ = std::make_unique<DeviceArray<uint32_t>>(context, "mcmc: report", MCMC_REPORT_SLOTS);
  no_plane_ = std::make_unique<DeviceArray<float>>(context, "mcmc: no plane distances", 1);
}

McmcStrategy::~McmcStrategy() = default;

McmcReport McmcStrategy::relocate_and_grow(TrainableGaussians& model, const McmcOptions& options,
                                           uint32_t step, const engine::Buffer* plane_distance) {
  options.check();
  engine::Context& ctx = *context_;
  const uint32_t n = static_cast<uint32_t>(model.size());
  McmcReport report;
  report.before = report.after = n;
  last_targets_ = 0;
  if (n == 0) return report;
  if (n > MCMC_MAX_GAUSSIANS)
    throw std::invalid_argument("mcmc: " + std::to_string(n) + " Gaussians exceed the strategy's limit of " +
                                std::to_string(MCMC_MAX_GAUSSIANS));
  if (plane_distance) check_binding(*plane_distance, n, 4, "mcmc: plane distances");
  grow(ctx, weight_, n, "mcmc: weight");
  grow(ctx, cdf_, n, "mcmc: cdf");
  grow(ctx, dead_, n, "mcmc: dead");
  grow(ctx, dead_rank_, n, "mcmc: dead rank");
  grow(ctx, copies_, n, "mcmc: copies");

  McmcParams p{};
  p.count = n;
  p.flags = plane_distance && std::isfinite(options.max_plane_distance_m) ? MCMC_FLAG_PLANE : 0u;
  p.seed = options.seed;
  p.step = step;
  p.min_opacity_logit = logit(options.min_opacity);
  p.max_plane_distance = options.max_plane_distance_m;
  p.min_opacity = options.min_opacity;

  // 1. Dead flags and weights, their scans; the dead count and the total weight come back in 32 bytes.
  {
    const DeviceGaussians& g = model.gaussians();
    engine::Sequence s(ctx);
    s.fill(report_->buffer(), 0u, MCMC_REPORT_SLOTS * 4);
    s.dispatch(*weights_, elementwise_groups(*context_, n, "mcmc/mcmc_weights"),
               {{WEIGHTS_BINDING_LOG_SCALES, &g.log_scales.buffer(), Access::kRead},
                {WEIGHTS_BINDING_MEANS, &g.means.buffer(), Access::kRead},
                {WEIGHTS_BINDING_QUATS, &g.quats.buffer(), Access::kRead},
                {WEIGHTS_BINDING_OPACITY_LOGITS, &g.opacity_logits.buffer(), Access::kRead},
                {WEIGHTS_BINDING_PLANE_DISTANCE, plane_distance ? plane_distance : &no_plane_->buffer(),
                 Access::kRead},
                {WEIGHTS_BINDING_WEIGHT, &weight_->buffer(), Access::kWrite},
                {WEIGHTS_BINDING_DEAD, &dead_->buffer(), Access::kWrite},
                {WEIGHTS_BINDING_REPORT, &report_->buffer(), Access::kReadWrite}},
               p);
    s.copy(weight_->buffer(), cdf_->buffer(), uint64_t{n} * 4);
    scan_.record(s, cdf_->buffer(), n);
    s.copy(dead_->buffer(), dead_rank_->buffer(), uint64_t{n} * 4);
    scan_.record(s, dead_rank_->buffer(), n);
    const uint64_t last = uint64_t{n - 1} * 4;
    s.copy(dead_rank_->buffer(), report_->buffer(), 4, last, MCMC_REPORT_LAST_DEAD_RANK * 4);
    s.copy(dead_->buffer(), report_->buffer(), 4, last, MCMC_REPORT_LAST_DEAD * 4);
    s.copy(cdf_->buffer(), report_->buffer(), 4, last, MCMC_REPORT_LAST_CDF * 4);
    s.copy(weight_->buffer(), report_->buffer(), 4, last, MCMC_REPORT_LAST_WEIGHT * 4);
    s.submit_and_wait();
  }
  const std::vector<uint32_t> r = report_->download();
  report.dead_nonfinite = r[MCMC_REPORT_DEAD_NONFINITE];
  report.dead_transparent = r[MCMC_REPORT_DEAD_TRANSPARENT];
  report.dead_plane = r[MCMC_REPORT_DEAD_PLANE];
  const uint32_t dead = r[MCMC_REPORT_LAST_DEAD_RANK] + r[MCMC_REPORT_LAST_DEAD];
  const uint64_t total_weight = uint64_t{r[MCMC_REPORT_LAST_CDF]} + r[MCMC_REPORT_LAST_WEIGHT];
  if (dead != report.dead())
    throw std::logic_error("mcmc: " + std::to_string(dead) + " dead rows disagree with the report (" +
                           report.to_string() + ")");
  if (total_weight == 0) return report;  // nothing alive to draw from: leave the model as it is

  const uint64_t wanted =
      static_cast<uint64_t>(std::floor(static_cast<double>(n) * (1.0 + double{options.growth})));
  const uint32_t target_rows = static_cast<uint32_t>(std::min<uint64_t>(options.max_gaussians, wanted));
  const uint32_t added = target_rows > n ? target_rows - n : 0u;
  const uint32_t targets = dead + added;
  if (targets == 0) return report;
  if (added > 0) model.grow_rows(n + added, options.max_gaussians);
  grow(ctx, dead_index_, dead, "mcmc: dead index");
  grow(ctx, source_, targets, "mcmc: source");
  grow(ctx, target_, targets, "mcmc: target");
  p.dead = dead;
  p.targets = targets;
  p.total_weight = static_cast<uint32_t>(total_weight);

  // 2. Draw sources, update them, copy their rows to the targets; moments of both restart.
  const DeviceGaussians& g = model.gaussians();
  engine::Sequence s(ctx);
  s.fill(copies_->buffer(), 0u, uint64_t{n} * 4);
  if (dead > 0)
    s.dispatch(*list_dead_, elementwise_groups(*context_, n, "mcmc/mcmc_list_dead"),
               {{LIST_BINDING_DEAD, &dead_->buffer(), Access::kRead},
                {LIST_BINDING_DEAD_RANK, &dead_rank_->buffer(), Access::kRead},
                {LIST_BINDING_DEAD_INDEX, &dead_index_->buffer(), Access::kWrite}},
               p);
  s.dispatch(*sample_, elementwise_groups(*context_, targets, "mcmc/mcmc_sample"),
             {{SAMPLE_BINDING_CDF, &cdf_->buffer(), Access::kRead},
              {SAMPLE_BINDING_DEAD_INDEX, &dead_index_->buffer(), Access::kRead},
              {SAMPLE_BINDING_SOURCE, &source_->buffer(), Access::kWrite},
              {SAMPLE_BINDING_TARGET, &target_->buffer(), Access::kWrite},
              {SAMPLE_BINDING_COPIES, &copies_->buffer(), Access::kReadWrite}},
             p);
  s.dispatch(*update_sources_, elementwise_groups(*context_, n, "mcmc/mcmc_update_sources"),
             {{UPDATE_BINDING_COPIES, &copies_->buffer(), Access::kRead},
              {UPDATE_BINDING_OPACITY_LOGITS, &g.opacity_logits.buffer(), Access::kReadWrite},
              {UPDATE_BINDING_LOG_SCALES, &g.log_scales.buffer(), Access::kReadWrite}},
             p);
  auto copy_rows = [&](const engine::Buffer& rows, uint32_t stride, uint32_t mode) {
    const CopyRowsParams cp{targets, stride, mode, 0u};
    s.dispatch(*copy_rows_, elementwise_groups(*context_, targets, "mcmc/mcmc_copy_rows"),
               {{COPY_BINDING_SOURCE, &source_->buffer(), Access::kRead},
                {COPY_BINDING_TARGET, &target_->buffer(), Access::kRead},
                {COPY_BINDING_ROWS, &rows, Access::kReadWrite}},
               cp);
  };
  for (const TrainableGaussians::RowArray& a : model.row_arrays()) {
    if (a.kind == TrainableGaussians::RowArray::kParameter) {
      copy_rows(*a.buffer, a.stride, COPY_MODE_SOURCE_TO_TARGET);
    } else {
      copy_rows(*a.buffer, a.stride, COPY_MODE_ZERO_TARGET);
      if (a.kind == TrainableGaussians::RowArray::kMoment)
        copy_rows(*a.buffer, a.stride, COPY_MODE_ZERO_SOURCE);
    }
  }
  s.submit_and_wait();
  last_targets_ = targets;
  report.relocated = dead;
  report.added = added;
  report.after = n + added;
  return report;
}

McmcStrategy::Draws McmcStrategy::last_draws() const {
  Draws d;
  if (last_targets_ == 0) return d;
  d.source = source_->download(0, last_targets_);
  d.target = target_->download(0, last_targets_);
  return d;
}

RegularizationWeights McmcStrategy::regularization_weights(const McmcOptions& options, uint32_t gaussians) {
  if (gaussians == 0) return {};
  return {static_cast<float>(double{options.opacity_reg} / gaussians),
          static_cast<float>(double{options.scale_reg} / (3.0 * gaussians))};
}

void McmcStrategy::record_regularization(engine::Sequence& sequence, const TrainableGaussians& model,
                                         const Rasterizer::DeviceGrads& grads,
                                         const McmcOptions& options) const {
  const uint32_t n = static_cast<uint32_t>(model.size());
  if (n == 0 || (options.opacity_reg == 0 && options.scale_reg == 0)) return;
  if (!grads.opacity_logits || !grads.log_scales)
    throw std::invalid_argument("mcmc regularization: no opacity or log-scale gradient buffer");
  check_binding(*grads.opacity_logits, n, 4, "mcmc regularization: opacity gradients");
  check_binding(*grads.log_scales, 3ull * n, 4, "mcmc regularization: log-scale gradients");
  const RegularizationWeights w = regularization_weights(options, n);
  McmcParams p{};
  p.count = n;
  p.opacity_reg = w.opacity;
  p.scale_reg = w.scale;
  const DeviceGaussians& g = model.gaussians();
  sequence.dispatch(*regularize_, elementwise_groups(*context_, n, "mcmc/mcmc_regularize"),
                    {{REG_BINDING_OPACITY_LOGITS, &g.opacity_logits.buffer(), Access::kRead},
                     {REG_BINDING_LOG_SCALES, &g.log_scales.buffer(), Access::kRead},
                     {REG_BINDING_GRAD_OPACITY, grads.opacity_logits, Access::kReadWrite},
                     {REG_BINDING_GRAD_LOG_SCALES, grads.log_scales, Access::kReadWrite}},
                    p);
}

void McmcStrategy::record_noise(engine::Sequence& sequence, const TrainableGaussians& model,
                                const McmcOptions& options, float means_lr, uint32_t step) const {
  const uint32_t n = static_cast<uint32_t>(model.size());
  const float scale = means_lr * options.noise_lr;
  if (n == 0 || !(scale > 0)) return;
  McmcParams p{};
  p.count = n;
  p.seed = options.seed;
  p.step = step;
  p.noise_scale = scale;
  const DeviceGaussians& g = model.gaussians();
  sequence.dispatch(*noise_, elementwise_groups(*context_, n, "mcmc/mcmc_noise"),
                    {{NOISE_BINDING_MEANS, &g.means.buffer(), Access::kReadWrite},
                     {NOISE_BINDING_LOG_SCALES, &g.log_scales.buffer(), Access::kRead},
                     {NOISE_BINDING_QUATS, &g.quats.buffer(), Access::kRead},
                     {NOISE_BINDING_OPACITY_LOGITS, &g.opacity_logits.buffer(), Access::kRead}},
                    p);
}

}  // namespace litgs::kernels
