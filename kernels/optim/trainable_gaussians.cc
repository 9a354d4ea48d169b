#include "kernels/optim/trainable_gaussians.h"

#include <algorithm>
#include <cmath>
#include <stdexcept>
#include <string>

#include "kernels/densify/densify_shared.h"
#include "kernels/device_growth.h"
#include "kernels/elementwise.h"
#include "kernels/optim/optim_shared.h"
#include "kernels/subgroup_kernel.h"

namespace litgs::kernels {

using engine::Access;
using engine::DeviceArray;

namespace {

std::array<uint32_t, kParamGroupCount> group_widths(uint32_t sh_values) {
  return {3, 3, 4, 1, sh_values};
}

const engine::Buffer& param_buffer(const DeviceGaussians& g, uint32_t group) {
  switch (group) {
    case kMeans:
      return g.means.buffer();
    case kLogScales:
      return g.log_scales.buffer();
    case kQuats:
      return g.quats.buffer();
    case kOpacityLogits:
      return g.opacity_logits.buffer();
    default:
      return g.sh.buffer();
  }
}

const engine::Buffer* grad_buffer(const Rasterizer::DeviceGrads& g, uint32_t group) {
  switch (group) {
    case kMeans:
      return g.means;
    case kLogScales:
      return g.log_scales;
    case kQuats:
      return g.quats;
    case kOpacityLogits:
      return g.opacity_logits;
    default:
      return g.sh;
  }
}

}  // namespace

// One full set of device arrays: parameters, moments and statistics, `capacity` rows each.
struct TrainableGaussians::Slot {
  std::unique_ptr<DeviceGaussians> params;
  std::array<std::unique_ptr<DeviceArray<float>>, kParamGroupCount> exp_avg, exp_avg_sq;
  std::unique_ptr<DeviceArray<float>> grad_accum, max_radius;
  std::unique_ptr<DeviceArray<uint32_t>> denom;
  size_t capacity = 0;
};

TrainableGaussians::TrainableGaussians(engine::Context& context, const GaussianModel& model, AdamOptions adam,
                                       bool densify_statistics)
    : TrainableGaussians(context, TrainingState::fresh(model), adam, densify_statistics) {}

TrainableGaussians::TrainableGaussians(engine::Context& context, const TrainingState& state, AdamOptions adam,
                                       bool densify_statistics)
    : context_(&context),
      adam_options_(adam),
      statistics_(densify_statistics),
      channels_(state.model.channels),
      sh_degree_(state.model.sh_degree),
      adam_(context),
      gaussian_adam_(context, state.model.channels, adam),
      scan_(context) {
  adam_options_.check();
  state.check();
  stats_ = make_kernel(context, "densify/densify_stats", STATS_BINDING_COUNT, sizeof(SplatView),
                       {{1, channels_}});  // CHANNELS: the rasterizer's gradient row stride
  candidates_ =
      make_kernel(context, "densify/densify_candidates", DECIDE_BINDING_COUNT, sizeof(DensifyParams));
  decide_ = make_kernel(context, "densify/densify_decide", DECIDE_BINDING_COUNT, sizeof(DensifyParams));
  scatter_rows_ =
      make_kernel(context, "densify/densify_scatter_rows", SCATTER_BINDING_COUNT, sizeof(ScatterParams));
  scatter_geometry_ =
      make_kernel(context, "densify/densify_scatter_geometry", GEOMETRY_BINDING_COUNT, sizeof(ScatterParams));
  reset_opacity_ =
      make_kernel(context, "densify/densify_reset_opacity", RESET_BINDING_COUNT, sizeof(ResetOpacityParams));
  adam_counters_ =
      std::make_unique<DeviceArray<uint32_t>>(context, "optim: adam counters", ADAM_COUNTER_SLOTS);
  adam_counters_->upload(std::vector<uint32_t>(ADAM_COUNTER_SLOTS, 0u));
  report_ = std::make_unique<DeviceArray<uint32_t>>(context, "densify: report", DENSIFY_REPORT_SLOTS);
  no_plane_ = std::make_unique<DeviceArray<float>>(context, "densify: no plane distances", 1);
  current_ = std::make_unique<Slot>();
  ensure_capacity(*current_, state.size());
  current_->params->count = state.size();
  upload_state(*current_, state);
}

void TrainableGaussians::require_statistics(const char* what) const {
  if (!statistics_)
    throw std::logic_error(std::string("TrainableGaussians::") + what +
                           ": this model keeps no densification statistics (made for the MCMC strategy)");
}

TrainableGaussians::~TrainableGaussians() = default;

const DeviceGaussians& TrainableGaussians::gaussians() const {
  return *current_->params;
}
size_t TrainableGaussians::size() const {
  return current_->params->count;
}
size_t TrainableGaussians::capacity() const {
  return current_->capacity;
}
uint32_t TrainableGaussians::sh_values() const {
  return (sh_degree_ + 1) * (sh_degree_ + 1) * channels_;
}

void TrainableGaussians::ensure_capacity(Slot& slot, size_t rows) {
  if (slot.params && slot.capacity >= rows) return;
  engine::Context& ctx = *context_;
  slot = Slot{};
  slot.capacity = std::max<size_t>(rows, 1);
  slot.params = std::make_unique<DeviceGaussians>(ctx, channels_, sh_degree_, 0, slot.capacity);
  const auto widths = group_widths(sh_values());
  for (uint32_t g = 0; g < kParamGroupCount; ++g) {
    slot.exp_avg[g] = std::make_unique<DeviceArray<float>>(
        ctx, std::string("optim: exp_avg ") + kParamGroupNames[g], slot.capacity * widths[g]);
    slot.exp_avg_sq[g] = std::make_unique<DeviceArray<float>>(
        ctx, std::string("optim: exp_avg_sq ") + kParamGroupNames[g], slot.capacity * widths[g]);
  }
  if (!statistics_) return;
  slot.grad_accum = std::make_unique<DeviceArray<float>>(ctx, "densify: grad accum", slot.capacity);
  slot.denom = std::make_unique<DeviceArray<uint32_t>>(ctx, "densify: denom", slot.capacity);
  slot.max_radius = std::make_unique<DeviceArray<float>>(ctx, "densify: max radius", slot.capacity);
}

void TrainableGaussians::upload_state(Slot& slot, const TrainingState& state) {
  slot.params->upload(state.model);
  for (uint32_t g = 0; g < kParamGroupCount; ++g) {
    slot.exp_avg[g]->upload(state.exp_avg[g]);
    slot.exp_avg_sq[g]->upload(state.exp_avg_sq[g]);
  }
  if (!statistics_) return;
  slot.grad_accum->upload(state.grad_accum);
  slot.denom->upload(state.denom);
  slot.max_radius->upload(state.max_radius);
}

void TrainableGaussians::record_adam_step(engine::Sequence& sequence, const Rasterizer::DeviceGrads& grads,
                                          const LearningRates& lr, uint32_t step, const FusedStep* fused) {
  const Slot& s = *current_;
  const uint64_t n = size();
  if (!grads.means) {
    if (!fused || !fused->tile_rects || !grads.grad2d)
      throw std::invalid_argument(
          "record_adam_step: no stored gradients, and no tile rectangles and camera to compute them from");
    GaussianAdamKernel::Target t;
    for (uint32_t g = 0; g < kParamGroupCount; ++g) {
      t.params[g] = &param_buffer(*s.params, g);
      t.exp_avg[g] = &s.exp_avg[g]->buffer();
      t.exp_avg_sq[g] = &s.exp_avg_sq[g]->buffer();
    }
    t.counters = &adam_counters_->buffer();
    t.tile_rects = fused->tile_rects;
    t.grad2d = grads.grad2d;
    gaussian_adam_.record(sequence, t, static_cast<uint32_t>(n), sh_values() / channels_, fused->camera,
                          adam_options_, step, lr, fused->regularization);
    return;
  }
  const auto widths = group_widths(sh_values());
  const float rates[kParamGroupCount] = {lr.means, lr.log_scales, lr.quats, lr.opacity_logits, lr.sh_dc};
  for (uint32_t g = 0; g < kParamGroupCount; ++g) {
    const engine::Buffer* grad = grad_buffer(grads, g);
    if (!grad)
      throw std::invalid_argument(std::string("record_adam_step: no gradient buffer for ") +
                                  kParamGroupNames[g]);
    AdamKernel::Target t{&param_buffer(*s.params, g), grad, &s.exp_avg[g]->buffer(),
                         &s.exp_avg_sq[g]->buffer(), &adam_counters_->buffer()};
    if (g == kSh)
      adam_.record(sequence, t, n * widths[g], adam_options_, step, lr.sh_dc, g, lr.sh_rest, widths[g],
                   channels_);
    else
      adam_.record(sequence, t, n * widths[g], adam_options_, step, rates[g], g);
  }
}

void TrainableGaussians::record_accumulate_stats(engine::Sequence& sequence,
                                                 const Rasterizer::DeviceGrads& grads,
                                                 const engine::Buffer& rects, const SplatCamera& camera) {
  camera.check();
  require_statistics("record_accumulate_stats");
  const Slot& s = *current_;
  const uint64_t n = size();
  if (!grads.grad2d) throw std::invalid_argument("record_accumulate_stats: no screen-space gradient buffer");
  check_binding(rects, 2 * n, 4, "densify stats: tile rects");
  check_binding(*grads.grad2d, n * (SPLAT_GRAD2D_FIXED + channels_), 4,
                "densify stats: screen-space gradients");
  const SplatView view =
      make_splat_view(camera, static_cast<uint32_t>(n), (sh_degree_ + 1) * (sh_degree_ + 1));
  const DeviceGaussians& g = *s.params;
  sequence.dispatch(*stats_, elementwise_groups(*context_, n, "densify/densify_stats"),
                    {{STATS_BINDING_MEANS, &g.means.buffer(), Access::kRead},
                     {STATS_BINDING_LOG_SCALES, &g.log_scales.buffer(), Access::kRead},
                     {STATS_BINDING_QUATS, &g.quats.buffer(), Access::kRead},
                     {STATS_BINDING_OPACITY_LOGITS, &g.opacity_logits.buffer(), Access::kRead},
                     {STATS_BINDING_TILE_RECTS, &rects, Access::kRead},
                     {STATS_BINDING_GRAD2D, grads.grad2d, Access::kRead},
                     {STATS_BINDING_GRAD_ACCUM, &s.grad_accum->buffer(), Access::kReadWrite},
                     {STATS_BINDING_DENOM, &s.denom->buffer(), Access::kReadWrite},
                     {STATS_BINDING_MAX_RADIUS, &s.max_radius->buffer(), Access::kReadWrite}},
                    view);
}

DensifyReport TrainableGaussians::densify_and_prune(const DensifyOptions& options, float scene_extent,
                                                    uint32_t step, const engine::Buffer* plane_distance) {
  require_statistics("densify_and_prune");
  engine::Context& ctx = *context_;
  const uint32_t n = static_cast<uint32_t>(size());
  const uint32_t sv = sh_values();
  const DensifyParams params =
      make_densify_params(options, scene_extent, step, n, sv, plane_distance != nullptr);
  DensifyReport report;
  report.before = n;
  if (n == 0) return report;
  if (plane_distance) check_binding(*plane_distance, n, 4, "densify: plane distances");
  grow(ctx, candidate_, n, "densify: candidate");
  grow(ctx, rank_, n, "densify: rank");
  grow(ctx, decision_, n, "densify: decision");
  grow(ctx, counts_, n, "densify: counts");
  grow(ctx, offsets_, n, "densify: offsets");

  // 1. Decide, count rows, scan: the new count and the report come back in one 48-byte readback.
  Slot& in = *current_;
  const DeviceGaussians& g = *in.params;
  const engine::Buffer& distances = plane_distance ? *plane_distance : no_plane_->buffer();
  engine::Sequence s1(ctx);
  s1.fill(report_->buffer(), 0u, DENSIFY_REPORT_SLOTS * sizeof(uint32_t));
  auto decide_bindings = [&](const engine::Kernel& kernel, bool decide) {
    s1.dispatch(kernel, elementwise_groups(*context_, n, kernel.name().c_str()),
                {{DECIDE_BINDING_MEANS, &g.means.buffer(), Access::kRead},
                 {DECIDE_BINDING_LOG_SCALES, &g.log_scales.buffer(), Access::kRead},
                 {DECIDE_BINDING_QUATS, &g.quats.buffer(), Access::kRead},
                 {DECIDE_BINDING_OPACITY_LOGITS, &g.opacity_logits.buffer(), Access::kRead},
                 {DECIDE_BINDING_SH, &g.sh.buffer(), Access::kRead},
                 {DECIDE_BINDING_GRAD_ACCUM, &in.grad_accum->buffer(), Access::kRead},
                 {DECIDE_BINDING_DENOM, &in.denom->buffer(), Access::kRead},
                 {DECIDE_BINDING_MAX_RADIUS, &in.max_radius->buffer(), Access::kRead},
                 {DECIDE_BINDING_PLANE_DISTANCE, &distances, Access::kRead},
                 {DECIDE_BINDING_CANDIDATE, &candidate_->buffer(), decide ? Access::kRead : Access::kWrite},
                 {DECIDE_BINDING_RANK, &rank_->buffer(), Access::kRead},
                 {DECIDE_BINDING_DECISION, &decision_->buffer(), Access::kWrite},
                 {DECIDE_BINDING_COUNTS, &counts_->buffer(), Access::kWrite},
                 {DECIDE_BINDING_REPORT, &report_->buffer(), Access::kReadWrite}},
                params);
  };
  decide_bindings(*candidates_, false);
  s1.copy(candidate_->buffer(), rank_->buffer(), uint64_t{n} * 4);
  scan_.record(s1, rank_->buffer(), n);
  decide_bindings(*decide_, true);
  s1.copy(counts_->buffer(), offsets_->buffer(), uint64_t{n} * 4);
  scan_.record(s1, offsets_->buffer(), n);
  s1.copy(offsets_->buffer(), report_->buffer(), 4, uint64_t{n - 1} * 4, DENSIFY_REPORT_LAST_OFFSET * 4);
  s1.copy(counts_->buffer(), report_->buffer(), 4, uint64_t{n - 1} * 4, DENSIFY_REPORT_LAST_COUNT * 4);
  s1.submit_and_wait();
  const std::vector<uint32_t> r = report_->download();
  report.cloned = r[DENSIFY_REPORT_CLONED];
  report.split = r[DENSIFY_REPORT_SPLIT];
  report.capped = r[DENSIFY_REPORT_CAPPED];
  report.pruned_nonfinite = r[DENSIFY_REPORT_PRUNED_NONFINITE];
  report.pruned_opacity = r[DENSIFY_REPORT_PRUNED_OPACITY];
  report.pruned_plane = r[DENSIFY_REPORT_PRUNED_PLANE];
  report.pruned_world_size = r[DENSIFY_REPORT_PRUNED_WORLD_SIZE];
  report.pruned_screen_size = r[DENSIFY_REPORT_PRUNED_SCREEN_SIZE];
  const uint64_t after = uint64_t{r[DENSIFY_REPORT_LAST_OFFSET]} + r[DENSIFY_REPORT_LAST_COUNT];
  report.after = static_cast<uint32_t>(after);
  if (after != uint64_t{n} + report.cloned + report.split - report.pruned())
    throw std::logic_error("densify_and_prune: row count " + std::to_string(after) +
                           " disagrees with the report (" + report.to_string() + ")");

  // 2. Scatter every array into the spare slot (grown geometrically), then swap.
  if (!spare_) spare_ = std::make_unique<Slot>();
  if (!spare_->params || spare_->capacity < after) {
    const uint64_t limit_rows = ctx.info().max_storage_buffer_range / (4ull * std::max<uint32_t>(sv, 4));
    size_t capacity = grown_capacity(in.capacity, after);  // kernels/device_growth.h, then capped
    if (options.max_gaussians > 0)
      capacity = std::min<size_t>(capacity, std::max<size_t>(options.max_gaussians, after));
    if (limit_rows > 0) capacity = std::min<size_t>(capacity, std::max<size_t>(limit_rows, after));
    spare_->params.reset();  // free the old spare first
    ensure_capacity(*spare_, capacity);
  }
  Slot& out = *spare_;
  out.params->count = after;
  engine::Sequence s2(ctx);
  ScatterParams sp{};
  sp.count = n;
  sp.seed = options.seed;
  sp.step = step;
  sp.log_split_divisor = params.log_split_divisor;
  const engine::Buffer& decision = decision_->buffer();
  const engine::Buffer& offsets = offsets_->buffer();
  s2.dispatch(*scatter_geometry_, elementwise_groups(*context_, n, "densify/densify_scatter_geometry"),
              {{GEOMETRY_BINDING_DECISION, &decision, Access::kRead},
               {GEOMETRY_BINDING_OFFSETS, &offsets, Access::kRead},
               {GEOMETRY_BINDING_MEANS, &g.means.buffer(), Access::kRead},
               {GEOMETRY_BINDING_LOG_SCALES, &g.log_scales.buffer(), Access::kRead},
               {GEOMETRY_BINDING_QUATS, &g.quats.buffer(), Access::kRead},
               {GEOMETRY_BINDING_MEANS_OUT, &out.params->means.buffer(), Access::kWrite},
               {GEOMETRY_BINDING_LOG_SCALES_OUT, &out.params->log_scales.buffer(), Access::kWrite}},
              sp);
  auto scatter = [&](const engine::Buffer& src, const engine::Buffer& dst, uint32_t stride, bool zero_new) {
    check_binding(dst, after * stride, 4, "densify scatter");
    ScatterParams rp = sp;
    rp.stride = stride;
    rp.zero_new = zero_new ? 1u : 0u;
    s2.dispatch(*scatter_rows_, elementwise_groups(*context_, n, "densify/densify_scatter_rows"),
                {{SCATTER_BINDING_DECISION, &decision, Access::kRead},
                 {SCATTER_BINDING_OFFSETS, &offsets, Access::kRead},
                 {SCATTER_BINDING_SRC, &src, Access::kRead},
                 {SCATTER_BINDING_DST, &dst, Access::kWrite}},
                rp);
  };
  const auto widths = group_widths(sv);
  for (uint32_t k : {uint32_t{kQuats}, uint32_t{kOpacityLogits}, uint32_t{kSh}})
    scatter(param_buffer(g, k), param_buffer(*out.params, k), widths[k], false);
  for (uint32_t k = 0; k < kParamGroupCount; ++k) {
    scatter(in.exp_avg[k]->buffer(), out.exp_avg[k]->buffer(), widths[k], true);
    scatter(in.exp_avg_sq[k]->buffer(), out.exp_avg_sq[k]->buffer(), widths[k], true);
  }
  if (options.reset_stats) {
    if (after > 0) {
      s2.fill(out.grad_accum->buffer(), 0u, after * 4);
      s2.fill(out.denom->buffer(), 0u, after * 4);
      s2.fill(out.max_radius->buffer(), 0u, after * 4);
    }
  } else {
    scatter(in.grad_accum->buffer(), out.grad_accum->buffer(), 1, true);
    scatter(in.denom->buffer(), out.denom->buffer(), 1, true);
    scatter(in.max_radius->buffer(), out.max_radius->buffer(), 1, true);
  }
  s2.submit_and_wait();
  std::swap(current_, spare_);
  return report;
}

void TrainableGaussians::record_reset_opacity(engine::Sequence& sequence, float reset_opacity) {
  if (!(reset_opacity > 0 && reset_opacity < 1))
    throw std::invalid_argument("record_reset_opacity: reset_opacity = " + std::to_string(reset_opacity) +
                                " must be in (0, 1)");
  const Slot& s = *current_;
  const uint32_t n = static_cast<uint32_t>(size());
  if (n == 0) return;
  ResetOpacityParams p{};
  p.count = n;
  p.max_logit = static_cast<float>(std::log(double{reset_opacity} / (1.0 - reset_opacity)));
  sequence.dispatch(*reset_opacity_, elementwise_groups(*context_, n, "densify/densify_reset_opacity"),
                    {{RESET_BINDING_OPACITY_LOGITS, &s.params->opacity_logits.buffer(), Access::kReadWrite}},
                    p);
  // 3DGS replaces the opacity tensor in the optimizer with fresh (zero) moments.
  sequence.fill(s.exp_avg[kOpacityLogits]->buffer(), 0u, uint64_t{n} * 4);
  sequence.fill(s.exp_avg_sq[kOpacityLogits]->buffer(), 0u, uint64_t{n} * 4);
}

void TrainableGaussians::load_state(const TrainingState& state) {
  state.check();
  if (state.model.channels != channels_ || state.model.sh_degree != sh_degree_)
    throw std::invalid_argument("TrainableGaussians::load_state: the state has " +
                                std::to_string(state.model.channels) + " channels and SH degree " +
                                std::to_string(state.model.sh_degree) + ", the model " +
                                std::to_string(channels_) + " and " + std::to_string(sh_degree_));
  ensure_capacity(*current_, state.size());
  current_->params->count = state.size();
  upload_state(*current_, state);
}

std::vector<TrainableGaussians::RowArray> TrainableGaussians::row_arrays() const {
  const Slot& s = *current_;
  const auto widths = group_widths(sh_values());
  std::vector<RowArray> out;
  for (uint32_t g = 0; g < kParamGroupCount; ++g)
    out.push_back({&param_buffer(*s.params, g), widths[g], RowArray::kParameter});
  for (uint32_t g = 0; g < kParamGroupCount; ++g) {
    out.push_back({&s.exp_avg[g]->buffer(), widths[g], RowArray::kMoment});
    out.push_back({&s.exp_avg_sq[g]->buffer(), widths[g], RowArray::kMoment});
  }
  if (!statistics_) return out;
  out.push_back({&s.grad_accum->buffer(), 1, RowArray::kStatistic});
  out.push_back({&s.denom->buffer(), 1, RowArray::kStatistic});
  out.push_back({&s.max_radius->buffer(), 1, RowArray::kStatistic});
  return out;
}

void TrainableGaussians::grow_rows(size_t rows, size_t capacity_cap) {
  const size_t n = size();
  if (rows < n)
    throw std::invalid_argument("TrainableGaussians::grow_rows: " + std::to_string(rows) + " rows < " +
                                std::to_string(n) + " in use");
  if (rows == n) return;
  if (rows > current_->capacity) {
    size_t capacity = grown_capacity(current_->capacity, rows);  // kernels/device_growth.h, then capped
    if (capacity_cap > 0) capacity = std::max(rows, std::min(capacity, capacity_cap));
    if (!spare_) spare_ = std::make_unique<Slot>();
    spare_->params.reset();  // free the old spare first
    ensure_capacity(*spare_, capacity);
    const std::vector<RowArray> from = row_arrays();
    std::swap(current_, spare_);
    const std::vector<RowArray> to = row_arrays();
    engine::Sequence copy(*context_);
    for (size_t a = 0; a < from.size(); ++a)
      copy.copy(*from[a].buffer, *to[a].buffer, uint64_t{n} * from[a].stride * 4);
    copy.submit_and_wait();
  }
  engine::Sequence zero(*context_);
  for (const RowArray& a : row_arrays())
    zero.fill(*a.buffer, 0u, uint64_t{rows - n} * a.stride * 4, uint64_t{n} * a.stride * 4);
  zero.submit_and_wait();
  current_->params->count = rows;
}

GaussianModel TrainableGaussians::download() const {
  return current_->params->download();
}

TrainingState TrainableGaussians::download_state() const {
  const Slot& s = *current_;
  const size_t n = size();
  const auto widths = group_widths(sh_values());
  TrainingState st;
  st.model = s.params->download();
  for (uint32_t g = 0; g < kParamGroupCount; ++g) {
    st.exp_avg[g] = s.exp_avg[g]->download(0, n * widths[g]);
    st.exp_avg_sq[g] = s.exp_avg_sq[g]->download(0, n * widths[g]);
  }
  if (!statistics_) {  // zeros, as a model that never accumulated them (checkpoints keep one layout)
    st.grad_accum.assign(n, 0.0f);
    st.denom.assign(n, 0u);
    st.max_radius.assign(n, 0.0f);
    return st;
  }
  st.grad_accum = s.grad_accum->download(0, n);
  st.denom = s.denom->download(0, n);
  st.max_radius = s.max_radius->download(0, n);
  return st;
}

std::array<uint32_t, kParamGroupCount> TrainableGaussians::nonfinite_grad_counts() const {
  const std::vector<uint32_t> c = adam_counters_->download();
  std::array<uint32_t, kParamGroupCount> out{};
  for (uint32_t g = 0; g < kParamGroupCount; ++g) out[g] = c[g];
  return out;
}

}  // namespace litgs::kernels
