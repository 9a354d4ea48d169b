#include "kernels/splat/rasterizer.h"

#include <algorithm>
#include <array>
#include <bit>
#include <stdexcept>
#include <string>

#include "kernels/device_growth.h"
#include "kernels/elementwise.h"
#include "kernels/limits.h"
#include "kernels/spirv_registry.h"
#include "kernels/splat/splat_shared.h"

namespace litgs::kernels {

using engine::Access;
using engine::DeviceArray;

namespace {

// Upper bounds on the loop iterations one subgroup spends per chunk of S list entries (S = subgroup size,
// C = channels), counting as lavapipe does: every loop entered costs its iterations plus one. They follow
// the loop structure of the kernels (rasterize_forward.comp, rasterize_backward.glsl): the chunk loop, the
// colour load, the four ballot words and their entries, and per entry the butterfly sum (log2 S steps), the
// atomic adds (compare-and-swap loops) or the deterministic mode's sum over the workgroup's subgroups.
// The forward's and the atomic backward's walks are do-while loops over one ballot word now (at most S
// iterations per chunk, no extra one): these bounds, made for the earlier for and while loops, still hold.
uint32_t log2_ceil(uint32_t v) {
  return static_cast<uint32_t>(std::bit_width(std::max(v, 1u) - 1));
}

uint32_t forward_loops_per_chunk(uint32_t S, uint32_t C) {
  return 1 + (C + 1) + 5 + (S + 4);
}

uint32_t backward_loops_per_chunk(uint32_t S, uint32_t C, bool deterministic, uint32_t invocations) {
  const uint32_t walk = 1 + (C + 1) + 5 + (S + 4) + S * (log2_ceil(S) + 1);
  if (!deterministic) return walk + 3 + 4 + 5 + (C + 1) + 2 * (SPLAT_GRAD2D_FIXED + C);
  const uint32_t subgroups = (invocations + S - 1) / S;
  const uint32_t sums_per_invocation = (3 * S + invocations - 1) / invocations;
  return walk + (sums_per_invocation + 1) * ((subgroups + 1) + 5);
}

// Entries per pass: whole chunks within RASTERIZE_PASS_LOOP_BUDGET, for every subgroup size the device may
// use.
template <class LoopsPerChunk>
uint32_t entries_within_budget(const engine::DeviceInfo& info, uint32_t invocations,
                               LoopsPerChunk loops_per_chunk) {
  uint32_t entries = 0xFFFFFFFFu;
  for (uint32_t S : {info.min_subgroup_size, info.subgroup_size, info.max_subgroup_size}) {
    // A subgroup wider than the workgroup walks chunks of the lanes that exist (footprint.glsl).
    S = std::clamp(S, 1u, invocations);
    entries = std::min(entries, RASTERIZE_PASS_LOOP_BUDGET / loops_per_chunk(S) * S);
  }
  return std::max(entries, 1u);
}

SplatView make_view(const SplatCamera& c, uint32_t count, uint32_t sh_coeffs) {
  SplatView v{};
  for (int col = 0; col < 3; ++col)
    for (int row = 0; row < 3; ++row) v.rot[col * 3 + row] = static_cast<float>(c.R_cam_world[col][row]);
  for (int a = 0; a < 3; ++a) v.trans[a] = static_cast<float>(c.t_cam_world[a]);
  v.fx = static_cast<float>(c.fx);
  v.fy = static_cast<float>(c.fy);
  v.cx = static_cast<float>(c.cx);
  v.cy = static_cast<float>(c.cy);
  v.near_m = static_cast<float>(c.near_m);
  v.width = c.width;
  v.height = c.height;
  v.tiles_x = (c.width + SPLAT_TILE_SIZE - 1) / SPLAT_TILE_SIZE;
  v.tiles_y = (c.height + SPLAT_TILE_SIZE - 1) / SPLAT_TILE_SIZE;
  v.count = count;
  v.sh_degree = c.sh_degree;
  v.sh_coeffs = sh_coeffs;
  return v;
}

// The pass's push constants: entries [p E, (p + 1) E) of every tile's list.
RasterizeParams pass_params(const SplatView& view, uint32_t pass, uint32_t entries_per_pass) {
  const uint64_t begin = uint64_t{pass} * entries_per_pass;
  return {view,
          {static_cast<uint32_t>(begin),
           static_cast<uint32_t>(std::min<uint64_t>(begin + entries_per_pass, 0xFFFFFFFFu))}};
}

}  // namespace

SplatView make_splat_view(const SplatCamera& camera, uint32_t count, uint32_t sh_coeffs) {
  return make_view(camera, count, sh_coeffs);
}

namespace {

// One four-float record per Gaussian (splat_shared.h PROJECT_BINDING_CENTRES, _CONICS).
using Float4 = std::array<float, 4>;

// The rasterize kernels' per-entry reads, as texels (splat_shared.h).
std::vector<engine::TexelBinding> rasterize_texel_bindings(uint32_t ids, uint32_t gaussians, uint32_t centres,
                                                           uint32_t conics, uint32_t colors) {
  return {{ids, VK_FORMAT_R32_UINT},
          {gaussians, VK_FORMAT_R32_UINT},
          {centres, VK_FORMAT_R32G32B32A32_SFLOAT},
          {conics, VK_FORMAT_R32G32B32A32_SFLOAT},
          {colors, VK_FORMAT_R32_SFLOAT}};
}

}  // namespace

struct Rasterizer::Buffers {
  // Per Gaussian.
  std::unique_ptr<DeviceArray<Float4>> centres, conics;  // [N] each
  std::unique_ptr<DeviceArray<float>> colors, grad2d;
  std::unique_ptr<DeviceArray<uint32_t>> rects, order;
  // [N + 1]: first the depth keys, sorted in place with `order` (then dead), then the tile counts in depth
  // order, scanned in place into offsets: one buffer for two lifetimes that do not overlap.
  std::unique_ptr<DeviceArray<uint32_t>> keys_then_offsets;
  std::unique_ptr<DeviceArray<float>> g_means, g_log_scales, g_quats, g_logits, g_sh;
  // Per intersection.
  std::unique_ptr<DeviceArray<uint32_t>> tile_keys, isect_ids, isect_gaussian;
  std::unique_ptr<DeviceArray<float>> isect_grads;
  // Per pixel and per tile.
  std::unique_ptr<DeviceArray<float>> image, depth, alpha, grad_image, grad_depth, grad_alpha;
  std::unique_ptr<DeviceArray<uint32_t>> last, ranges;
  std::unique_ptr<DeviceArray<uint32_t>> corners;      // [(tiles_y + 1) * (tiles_x + 1)] list lengths
  std::unique_ptr<DeviceArray<float>> backward_state;  // [2 + C][H][W] between backward passes (else [1])
  std::unique_ptr<DeviceArray<uint32_t>> counters;     // [SPLAT_COUNTER_COUNT]
  std::unique_ptr<DeviceArray<uint32_t>> readback;     // [SPLAT_COUNTER_COUNT] host-visible copy
};

DeviceGaussians::DeviceGaussians(engine::Context& context, const GaussianModel& model)
    : count(model.size()),
      channels(model.channels),
      sh_degree(model.sh_degree),
      means(context, "gaussians: means", model.size() * 3),
      log_scales(context, "gaussians: log_scales", model.size() * 3),
      quats(context, "gaussians: quats", model.size() * 4),
      opacity_logits(context, "gaussians: opacity_logits", model.size()),
      sh(context, "gaussians: sh", model.sh.size()) {
  upload(model);
}

DeviceGaussians::DeviceGaussians(engine::Context& context, uint32_t channels_in, uint32_t sh_degree_in,
                                 size_t count_in, size_t capacity_in)
    : count(count_in),
      channels(channels_in),
      sh_degree(sh_degree_in),
      means(context, "gaussians: means", std::max<size_t>(capacity_in, 1) * 3),
      log_scales(context, "gaussians: log_scales", std::max<size_t>(capacity_in, 1) * 3),
      quats(context, "gaussians: quats", std::max<size_t>(capacity_in, 1) * 4),
      opacity_logits(context, "gaussians: opacity_logits", std::max<size_t>(capacity_in, 1)),
      sh(context, "gaussians: sh",
         std::max<size_t>(capacity_in, 1) * (sh_degree_in + 1) * (sh_degree_in + 1) * channels_in) {
  if (count_in > capacity_in)
    throw std::invalid_argument("DeviceGaussians: count " + std::to_string(count_in) + " exceeds capacity " +
                                std::to_string(capacity_in));
}

void DeviceGaussians::upload(const GaussianModel& model) {
  model.check();
  if (model.size() != count || model.channels != channels || model.sh_degree != sh_degree)
    throw std::invalid_argument("DeviceGaussians::upload: the model's size, channels or SH degree changed");
  means.upload(model.means);
  log_scales.upload(model.log_scales);
  quats.upload(model.quats);
  opacity_logits.upload(model.opacity_logits);
  sh.upload(model.sh);
}

GaussianModel DeviceGaussians::download() const {
  GaussianModel m;
  m.channels = channels;
  m.sh_degree = sh_degree;
  m.means = means.download(0, count * 3);
  m.log_scales = log_scales.download(0, count * 3);
  m.quats = quats.download(0, count * 4);
  m.opacity_logits = opacity_logits.download(0, count);
  m.sh = sh.download(0, count * m.sh_coeffs() * channels);
  return m;
}

Rasterizer::Rasterizer(engine::Context& context, uint32_t channels, RasterizerOptions options)
    : context_(&context),
      channels_(channels),
      options_(options),
      sort_(context),
      scan_(context),
      buffers_(std::make_unique<Buffers>()) {
  if (channels < 1 || channels > SPLAT_MAX_CHANNELS)
    throw std::invalid_argument("Rasterizer: channels = " + std::to_string(channels) + ", must be 1.." +
                                std::to_string(SPLAT_MAX_CHANNELS));
  const VkFormat f1 = VK_FORMAT_R32_SFLOAT, f4 = VK_FORMAT_R32G32B32A32_SFLOAT;
  project_ = make("splat/project", PROJECT_BINDING_COUNT, sizeof(SplatView), {},
                  {{PROJECT_BINDING_MEANS, f1},
                   {PROJECT_BINDING_LOG_SCALES, f1},
                   {PROJECT_BINDING_QUATS, f4},
                   {PROJECT_BINDING_OPACITY_LOGITS, f1},
                   {PROJECT_BINDING_SH, f1}});
  gather_ = make("splat/gather_counts", GATHER_BINDING_COUNT, sizeof(SplatView));
  lengths_ = make("splat/tile_list_lengths", LENGTHS_BINDING_COUNT, sizeof(SplatView));
  emit_ = make("splat/emit_intersections", EMIT_BINDING_COUNT, sizeof(SplatView));
  ranges_ = make("splat/tile_ranges", RANGES_BINDING_COUNT, sizeof(SplatView));
  const engine::DeviceInfo& info = context.info();
  if (options_.pixels_per_invocation != 0 && options_.pixels_per_invocation != 1 &&
      options_.pixels_per_invocation != 8)
    throw std::invalid_argument(
        "Rasterizer: pixels_per_invocation = " + std::to_string(options_.pixels_per_invocation) +
        ", must be 0 (auto), 1 or 8");
  pixels_per_invocation_ =
      options_.pixels_per_invocation ? options_.pixels_per_invocation : (info.type == "cpu" ? 8u : 1u);
  // The rasterize kernels' layout (footprint.glsl): 8x4 invocations of 2x4 pixels, or 16x16 of one.
  const bool blocks = pixels_per_invocation_ == 8;
  const uint32_t group_x = blocks ? 8 : SPLAT_TILE_SIZE, group_y = blocks ? 4 : SPLAT_TILE_SIZE;
  const uint32_t invocations = group_x * group_y;
  const std::vector<engine::SpecConstant> layout = {{SPLAT_SPEC_PIXEL_BLOCK, pixels_per_invocation_},
                                                    {SPLAT_SPEC_GROUP_X, group_x},
                                                    {SPLAT_SPEC_GROUP_Y, group_y}};
  forward_ = make("splat/rasterize_forward", FWD_BINDING_COUNT, sizeof(RasterizeParams), layout,
                  rasterize_texel_bindings(FWD_BINDING_ISECT_IDS, FWD_BINDING_ISECT_GAUSSIAN,
                                           FWD_BINDING_CENTRES, FWD_BINDING_CONICS, FWD_BINDING_COLORS));
  const char* backward = options_.deterministic ? "splat/rasterize_backward_deterministic"
                         : uses_float_atomics() ? "splat/rasterize_backward_float_atomics"
                                                : "splat/rasterize_backward_cas_atomics";
  std::vector<engine::SpecConstant> backward_constants = layout;
  backward_constants.push_back({2, options_.depth_gradient_to_opacity ? 1u : 0u});
  backward_ = make(backward, BWD_BINDING_COUNT, sizeof(RasterizeParams), backward_constants,
                   rasterize_texel_bindings(BWD_BINDING_ISECT_IDS, BWD_BINDING_ISECT_GAUSSIAN,
                                            BWD_BINDING_CENTRES, BWD_BINDING_CONICS, BWD_BINDING_COLORS));
  reduce_ = make("splat/reduce_isect_grads", REDUCE_BINDING_COUNT, sizeof(SplatView));
  project_backward_ = make("splat/project_backward", PBWD_BINDING_COUNT, sizeof(SplatView), {},
                           {{PBWD_BINDING_MEANS, f1},
                            {PBWD_BINDING_LOG_SCALES, f1},
                            {PBWD_BINDING_QUATS, f4},
                            {PBWD_BINDING_OPACITY_LOGITS, f1},
                            {PBWD_BINDING_SH, f1},
                            {PBWD_BINDING_GRAD2D, f1}});
  buffers_->counters =
      std::make_unique<DeviceArray<uint32_t>>(context, "splat: counters", SPLAT_COUNTER_COUNT);
  buffers_->counters->upload(std::vector<uint32_t>(SPLAT_COUNTER_COUNT, 0u));
  buffers_->readback = std::make_unique<DeviceArray<uint32_t>>(
      context, "splat: readback", SPLAT_COUNTER_COUNT, engine::MemoryKind::kHostVisible);
  forward_entries_per_pass_ = options_.entries_per_pass
                                  ? options_.entries_per_pass
                                  : entries_within_budget(info, invocations, [&](uint32_t S) {
                                      return forward_loops_per_chunk(S, channels);
                                    });
  backward_entries_per_pass_ =
      options_.entries_per_pass
          ? options_.entries_per_pass
          : entries_within_budget(info, invocations, [&](uint32_t S) {
              return backward_loops_per_chunk(S, channels, options_.deterministic, invocations);
            });
}

uint32_t Rasterizer::passes_for(uint32_t entries_per_pass) const {
  return static_cast<uint32_t>(
      std::max<uint64_t>(1, (uint64_t{longest_tile_list_} + entries_per_pass - 1) / entries_per_pass));
}

RasterizerCounters Rasterizer::read_counters() const {
  const std::vector<uint32_t> c = buffers_->counters->download();
  RasterizerCounters r;
  r.culled_nonfinite = c[SPLAT_COUNTER_CULLED_NONFINITE];
  r.longest_tile_list = longest_tile_list_;
  r.forward_passes = forward_passes_;
  r.backward_passes = backward_passes_;
  r.walks_cut_short = uint64_t{c[SPLAT_COUNTER_FORWARD_WALKS_CUT]} + c[SPLAT_COUNTER_BACKWARD_WALKS_CUT];
  r.contributions = c[SPLAT_COUNTER_CONTRIBUTIONS];
  return r;
}

Rasterizer::~Rasterizer() = default;

bool Rasterizer::uses_float_atomics() const {
  return !options_.deterministic && !options_.force_cas_atomics && context_->info().float_atomic_add;
}

std::unique_ptr<engine::Kernel> Rasterizer::make(const char* name, uint32_t bindings,
                                                 uint32_t push_constant_bytes,
                                                 std::vector<engine::SpecConstant> extra_constants,
                                                 std::vector<engine::TexelBinding> texel_bindings) {
  engine::KernelDesc desc;
  desc.name = name;
  desc.spirv = spirv(name);
  desc.binding_count = bindings;
  desc.push_constant_bytes = push_constant_bytes;
  desc.texel_bindings = std::move(texel_bindings);
  desc.spec_constants = {{1, channels_}};
  desc.spec_constants.insert(desc.spec_constants.end(), extra_constants.begin(), extra_constants.end());
  return std::make_unique<engine::Kernel>(*context_, std::move(desc));
}

void Rasterizer::append_profile(const engine::Sequence& sequence) {
  for (const auto& k : sequence.profile()) {
    auto it = std::find_if(profile_.begin(), profile_.end(), [&](const auto& p) { return p.name == k.name; });
    if (it == profile_.end()) {
      profile_.push_back(k);
    } else {
      it->ms += k.ms;
      it->dispatches += k.dispatches;
    }
  }
}

void Rasterizer::forward(const DeviceGaussians& g, const SplatCamera& camera) {
  camera.check();
  if (g.channels != channels_)
    throw std::invalid_argument("Rasterizer::forward: the model has " + std::to_string(g.channels) +
                                " channels, the rasterizer was built for " + std::to_string(channels_));
  if (camera.sh_degree > g.sh_degree)
    throw std::invalid_argument("Rasterizer::forward: camera.sh_degree " + std::to_string(camera.sh_degree) +
                                " exceeds the model's degree " + std::to_string(g.sh_degree));
  if (g.size() > 0xFFFFFFFFull) throw std::length_error("Rasterizer::forward: more than 2^32 Gaussians");
  engine::Context& ctx = *context_;
  Buffers& b = *buffers_;
  const uint32_t n = static_cast<uint32_t>(g.size());
  const uint32_t K = (g.sh_degree + 1) * (g.sh_degree + 1);
  const size_t pixels = static_cast<size_t>(camera.width) * camera.height;
  SplatView view = make_view(camera, n, K);
  const size_t tiles = static_cast<size_t>(view.tiles_x) * view.tiles_y;
  // gather_counts sums a subgroup's tile counts in 32 bits: at most 128 lanes of at most `tiles` each.
  if (tiles > (size_t{1} << 24))
    throw std::invalid_argument("Rasterizer::forward: " + std::to_string(camera.width) + "x" +
                                std::to_string(camera.height) + " pixels is more than 2^24 tiles");
  const size_t corner_cells = static_cast<size_t>(view.tiles_x + 1) * (view.tiles_y + 1);

  grow(ctx, b.centres, n, "splat: centres");  // mean2d, depth, opacity
  grow(ctx, b.conics, n, "splat: conics");    // conic, alpha reach
  grow(ctx, b.colors, size_t{n} * channels_, "splat: colors");
  grow(ctx, b.rects, 2 * size_t{n}, "splat: tile rects");  // packed 16-bit (splat/tile_rect.glsl)
  grow(ctx, b.order, n, "splat: depth order");
  grow(ctx, b.keys_then_offsets, size_t{n} + 1, "splat: depth keys, then tile offsets");
  grow(ctx, b.corners, corner_cells, "splat: tile corners");
  profile_.clear();

  // 1. Project, sort by depth, count tiles per depth rank (and their exact total), scan, list lengths.
  engine::Sequence s1(ctx);
  // Zero the per-render counters; the walks-cut counters after them keep running.
  s1.fill(b.counters->buffer(), 0u, (SPLAT_COUNTER_MAX_LIST + 1) * sizeof(uint32_t));
  s1.fill(b.counters->buffer(), 0u, sizeof(uint32_t), SPLAT_COUNTER_CONTRIBUTIONS * sizeof(uint32_t));
  s1.fill(b.corners->buffer(), 0u, corner_cells * sizeof(uint32_t));
  s1.fill(b.keys_then_offsets->buffer(), 0u, sizeof(uint32_t), uint64_t{n} * sizeof(uint32_t));
  s1.dispatch(*project_, elementwise_groups(*context_, n, "splat/project"),
              {{PROJECT_BINDING_MEANS, &g.means.buffer(), Access::kRead},
               {PROJECT_BINDING_LOG_SCALES, &g.log_scales.buffer(), Access::kRead},
               {PROJECT_BINDING_QUATS, &g.quats.buffer(), Access::kRead},
               {PROJECT_BINDING_OPACITY_LOGITS, &g.opacity_logits.buffer(), Access::kRead},
               {PROJECT_BINDING_SH, &g.sh.buffer(), Access::kRead},
               {PROJECT_BINDING_CENTRES, &b.centres->buffer(), Access::kWrite},
               {PROJECT_BINDING_CONICS, &b.conics->buffer(), Access::kWrite},
               {PROJECT_BINDING_COLORS, &b.colors->buffer(), Access::kWrite},
               {PROJECT_BINDING_TILE_RECTS, &b.rects->buffer(), Access::kWrite},
               {PROJECT_BINDING_DEPTH_KEYS, &b.keys_then_offsets->buffer(), Access::kWrite},
               {PROJECT_BINDING_ORDER, &b.order->buffer(), Access::kWrite},
               {PROJECT_BINDING_COUNTERS, &b.counters->buffer(), Access::kReadWrite}},
              view);
  sort_.record(s1, *b.keys_then_offsets, *b.order, n, 32);  // element n is not touched
  s1.dispatch(*gather_, elementwise_groups(*context_, n, "splat/gather_counts"),
              {{GATHER_BINDING_ORDER, &b.order->buffer(), Access::kRead},
               {GATHER_BINDING_TILE_RECTS, &b.rects->buffer(), Access::kRead},
               {GATHER_BINDING_COUNTS, &b.keys_then_offsets->buffer(), Access::kWrite},
               {GATHER_BINDING_CORNERS, &b.corners->buffer(), Access::kReadWrite},
               {GATHER_BINDING_COUNTERS, &b.counters->buffer(), Access::kReadWrite}},
              view);
  scan_.record(s1, b.keys_then_offsets->buffer(), n + 1);  // element n (zeroed above) becomes the total
  s1.dispatch(*lengths_, {1},
              {{LENGTHS_BINDING_CORNERS, &b.corners->buffer(), Access::kReadWrite},
               {LENGTHS_BINDING_COUNTERS, &b.counters->buffer(), Access::kReadWrite}},
              view);
  s1.copy(b.counters->buffer(), b.readback->buffer(), SPLAT_COUNTER_COUNT * sizeof(uint32_t));
  s1.submit_and_wait();
  append_profile(s1);

  // The one readback: how many (tile, Gaussian) intersections to emit and sort, and the longest tile list
  // (how many rasterize passes it takes).
  const std::vector<uint32_t> c = b.readback->download();
  const uint64_t m = (uint64_t{c[SPLAT_COUNTER_ISECT_HI]} << 32) | c[SPLAT_COUNTER_ISECT_LO];
  if (m > 0xFFFFFFFFull)
    throw std::length_error(
        "Rasterizer::forward: " + std::to_string(m) + " tile intersections (" + std::to_string(n) +
        " Gaussians on " + std::to_string(tiles) +
        " tiles) exceed the 2^32 an intersection id can index; render fewer or smaller Gaussians");
  // The rasterize kernels read the intersection lists as texels (one element per intersection).
  if (m > ctx.info().max_texel_buffer_elements)
    throw std::length_error("Rasterizer::forward: " + std::to_string(m) + " tile intersections exceed " +
                            ctx.info().name + "'s maxTexelBufferElements " +
                            std::to_string(ctx.info().max_texel_buffer_elements) +
                            "; render fewer or smaller Gaussians, or at a lower resolution");
  intersections_ = m;
  longest_tile_list_ = c[SPLAT_COUNTER_MAX_LIST];
  forward_walks_cut_before_ = c[SPLAT_COUNTER_FORWARD_WALKS_CUT];
  forward_passes_ = passes_for(forward_entries_per_pass_);
  // Per-pixel and per-intersection buffers only now that the render is known to fit.
  grow(ctx, b.image, pixels * channels_, "splat: image");
  grow(ctx, b.depth, pixels, "splat: expected depth");
  grow(ctx, b.alpha, pixels, "splat: alpha");
  grow(ctx, b.last, pixels, "splat: last");
  grow(ctx, b.ranges, 2 * tiles, "splat: tile ranges");
  grow(ctx, b.tile_keys, m, "splat: tile keys");
  grow(ctx, b.isect_ids, m, "splat: intersection ids");
  grow(ctx, b.isect_gaussian, m, "splat: intersection gaussians");

  // 2. Emit intersections in depth order, stable sort by tile, tile ranges, blend in passes over the lists.
  engine::Sequence s2(ctx);
  s2.fill(b.ranges->buffer(), 0u, 2 * tiles * sizeof(uint32_t));
  s2.dispatch(*emit_, elementwise_groups(*context_, n, "splat/emit_intersections"),
              {{EMIT_BINDING_ORDER, &b.order->buffer(), Access::kRead},
               {EMIT_BINDING_TILE_RECTS, &b.rects->buffer(), Access::kRead},
               {EMIT_BINDING_OFFSETS, &b.keys_then_offsets->buffer(), Access::kRead},
               {EMIT_BINDING_TILE_KEYS, &b.tile_keys->buffer(), Access::kWrite},
               {EMIT_BINDING_ISECT_IDS, &b.isect_ids->buffer(), Access::kWrite},
               {EMIT_BINDING_ISECT_GAUSSIAN, &b.isect_gaussian->buffer(), Access::kWrite}},
              view);
  const uint32_t tile_bits = static_cast<uint32_t>(std::max<size_t>(1, std::bit_width(tiles - 1)));
  sort_.record(s2, *b.tile_keys, *b.isect_ids, static_cast<uint32_t>(m), tile_bits);
  SplatView ranges_view = view;
  ranges_view.count = static_cast<uint32_t>(m);
  s2.dispatch(*ranges_, elementwise_groups(*context_, m, "splat/tile_ranges"),
              {{RANGES_BINDING_TILE_KEYS, &b.tile_keys->buffer(), Access::kRead},
               {RANGES_BINDING_RANGES, &b.ranges->buffer(), Access::kReadWrite}},
              ranges_view);
  for (uint32_t pass = 0; pass < forward_passes_; ++pass)
    s2.dispatch(*forward_, {view.tiles_x, view.tiles_y},
                {{FWD_BINDING_RANGES, &b.ranges->buffer(), Access::kRead},
                 {FWD_BINDING_ISECT_IDS, &b.isect_ids->buffer(), Access::kRead},
                 {FWD_BINDING_ISECT_GAUSSIAN, &b.isect_gaussian->buffer(), Access::kRead},
                 {FWD_BINDING_CENTRES, &b.centres->buffer(), Access::kRead},
                 {FWD_BINDING_CONICS, &b.conics->buffer(), Access::kRead},
                 {FWD_BINDING_COLORS, &b.colors->buffer(), Access::kRead},
                 {FWD_BINDING_IMAGE, &b.image->buffer(), Access::kReadWrite},
                 {FWD_BINDING_DEPTH, &b.depth->buffer(), Access::kReadWrite},
                 {FWD_BINDING_ALPHA, &b.alpha->buffer(), Access::kReadWrite},
                 {FWD_BINDING_LAST, &b.last->buffer(), Access::kReadWrite},
                 {FWD_BINDING_COUNTERS, &b.counters->buffer(), Access::kReadWrite}},
                pass_params(view, pass, forward_entries_per_pass_));
  s2.submit_and_wait();
  append_profile(s2);
  last_gaussians_ = &g;
  last_camera_ = camera;
}

RenderImages<float> Rasterizer::download_images() {
  if (!last_gaussians_) throw std::logic_error("Rasterizer::download_images before forward");
  const Buffers& b = *buffers_;
  const size_t pixels = static_cast<size_t>(last_camera_.width) * last_camera_.height;
  RenderImages<float> out;
  out.width = last_camera_.width;
  out.height = last_camera_.height;
  out.channels = channels_;
  out.image = b.image->download(0, pixels * channels_);
  out.depth = b.depth->download(0, pixels);
  out.alpha = b.alpha->download(0, pixels);
  out.last = b.last->download(0, pixels);
  const std::vector<uint32_t> c = b.counters->download();
  out.culled_nonfinite = c[SPLAT_COUNTER_CULLED_NONFINITE];
  out.walks_cut_short = c[SPLAT_COUNTER_FORWARD_WALKS_CUT] - forward_walks_cut_before_;
  out.intersections = intersections_;
  return out;
}

void Rasterizer::backward(const RenderGradInput& grad) {
  if (!last_gaussians_) throw std::logic_error("Rasterizer::backward before forward");
  const size_t pixels = static_cast<size_t>(last_camera_.width) * last_camera_.height;
  if (grad.image.size() != pixels * channels_)
    throw std::invalid_argument("Rasterizer::backward: grad image has " + std::to_string(grad.image.size()) +
                                " values, expected C*H*W = " + std::to_string(pixels * channels_));
  for (const auto* v : {&grad.depth, &grad.alpha})
    if (!v->empty() && v->size() != pixels)
      throw std::invalid_argument("Rasterizer::backward: grad depth/alpha has " + std::to_string(v->size()) +
                                  " values, expected H*W = " + std::to_string(pixels) + " (or none)");
  upstream_buffers();
  Buffers& b = *buffers_;
  b.grad_image->upload(grad.image);
  b.grad_depth->upload(grad.depth.empty() ? std::vector<float>(pixels, 0.0f) : grad.depth);
  b.grad_alpha->upload(grad.alpha.empty() ? std::vector<float>(pixels, 0.0f) : grad.alpha);
  engine::Sequence s(*context_);
  record_backward(s);
  s.submit_and_wait();
  append_profile(s);
}

Rasterizer::DeviceOutputs Rasterizer::device_outputs() const {
  if (!last_gaussians_) throw std::logic_error("Rasterizer::device_outputs before forward");
  const Buffers& b = *buffers_;
  return {&b.image->buffer(), &b.depth->buffer(), &b.alpha->buffer(), &b.rects->buffer(),
          &b.counters->buffer()};
}

Rasterizer::DeviceUpstream Rasterizer::upstream_buffers() {
  if (!last_gaussians_) throw std::logic_error("Rasterizer::upstream_buffers before forward");
  engine::Context& ctx = *context_;
  Buffers& b = *buffers_;
  const size_t pixels = static_cast<size_t>(last_camera_.width) * last_camera_.height;
  grow(ctx, b.grad_image, pixels * channels_, "splat: grad image");
  grow(ctx, b.grad_depth, pixels, "splat: grad depth");
  grow(ctx, b.grad_alpha, pixels, "splat: grad alpha");
  return {&b.grad_image->buffer(), &b.grad_depth->buffer(), &b.grad_alpha->buffer()};
}

Rasterizer::DeviceGrads Rasterizer::record_backward(engine::Sequence& s) {
  if (!last_gaussians_) throw std::logic_error("Rasterizer::record_backward before forward");
  engine::Context& ctx = *context_;
  Buffers& b = *buffers_;
  const DeviceGaussians& g = *last_gaussians_;
  const uint32_t n = static_cast<uint32_t>(g.size());
  const uint32_t K = (g.sh_degree + 1) * (g.sh_degree + 1);
  const SplatView view = make_view(last_camera_, n, K);
  const uint32_t stride = SPLAT_GRAD2D_FIXED + channels_;
  upstream_buffers();
  grow(ctx, b.grad2d, size_t{n} * stride, "splat: grad2d");
  if (options_.deterministic) grow(ctx, b.isect_grads, intersections_ * stride, "splat: intersection grads");
  backward_passes_ = passes_for(backward_entries_per_pass_);
  const size_t pixels = static_cast<size_t>(last_camera_.width) * last_camera_.height;
  grow(ctx, b.backward_state, backward_passes_ > 1 ? pixels * (2 + channels_) : 1, "splat: backward state");
  const engine::Buffer& rows = options_.deterministic ? b.isect_grads->buffer() : b.grad2d->buffer();
  const uint64_t row_values = options_.deterministic ? intersections_ * stride : uint64_t{n} * stride;
  s.fill(rows, 0u, row_values * sizeof(float));
  for (uint32_t pass = backward_passes_; pass-- > 0;)  // last segment first
    s.dispatch(*backward_, {view.tiles_x, view.tiles_y},
               {{BWD_BINDING_RANGES, &b.ranges->buffer(), Access::kRead},
                {BWD_BINDING_ISECT_IDS, &b.isect_ids->buffer(), Access::kRead},
                {BWD_BINDING_ISECT_GAUSSIAN, &b.isect_gaussian->buffer(), Access::kRead},
                {BWD_BINDING_CENTRES, &b.centres->buffer(), Access::kRead},
                {BWD_BINDING_CONICS, &b.conics->buffer(), Access::kRead},
                {BWD_BINDING_COLORS, &b.colors->buffer(), Access::kRead},
                {BWD_BINDING_DEPTH, &b.depth->buffer(), Access::kRead},
                {BWD_BINDING_ALPHA, &b.alpha->buffer(), Access::kRead},
                {BWD_BINDING_LAST, &b.last->buffer(), Access::kRead},
                {BWD_BINDING_GRAD_IMAGE, &b.grad_image->buffer(), Access::kRead},
                {BWD_BINDING_GRAD_DEPTH, &b.grad_depth->buffer(), Access::kRead},
                {BWD_BINDING_GRAD_ALPHA, &b.grad_alpha->buffer(), Access::kRead},
                {BWD_BINDING_GRAD2D, &rows, Access::kReadWrite},
                {BWD_BINDING_STATE, &b.backward_state->buffer(), Access::kReadWrite},
                {BWD_BINDING_COUNTERS, &b.counters->buffer(), Access::kReadWrite}},
               pass_params(view, pass, backward_entries_per_pass_));
  if (options_.deterministic)
    s.dispatch(*reduce_, elementwise_groups(*context_, n, "splat/reduce_isect_grads"),
               {{REDUCE_BINDING_ORDER, &b.order->buffer(), Access::kRead},
                {REDUCE_BINDING_OFFSETS, &b.keys_then_offsets->buffer(), Access::kRead},
                {REDUCE_BINDING_ISECT_GRADS, &b.isect_grads->buffer(), Access::kRead},
                {REDUCE_BINDING_GRAD2D, &b.grad2d->buffer(), Access::kWrite}},
               view);
  if (!options_.parameter_gradients)
    return {nullptr, nullptr, nullptr, nullptr, nullptr, &b.grad2d->buffer()};
  grow(ctx, b.g_means, 3 * size_t{n}, "splat: grad means");
  grow(ctx, b.g_log_scales, 3 * size_t{n}, "splat: grad log_scales");
  grow(ctx, b.g_quats, 4 * size_t{n}, "splat: grad quats");
  grow(ctx, b.g_logits, n, "splat: grad opacity_logits");
  grow(ctx, b.g_sh, size_t{n} * K * channels_, "splat: grad sh");
  s.dispatch(*project_backward_, elementwise_groups(*context_, n, "splat/project_backward"),
             {{PBWD_BINDING_MEANS, &g.means.buffer(), Access::kRead},
              {PBWD_BINDING_LOG_SCALES, &g.log_scales.buffer(), Access::kRead},
              {PBWD_BINDING_QUATS, &g.quats.buffer(), Access::kRead},
              {PBWD_BINDING_OPACITY_LOGITS, &g.opacity_logits.buffer(), Access::kRead},
              {PBWD_BINDING_SH, &g.sh.buffer(), Access::kRead},
              {PBWD_BINDING_TILE_RECTS, &b.rects->buffer(), Access::kRead},
              {PBWD_BINDING_GRAD2D, &b.grad2d->buffer(), Access::kRead},
              {PBWD_BINDING_GRAD_MEANS, &b.g_means->buffer(), Access::kWrite},
              {PBWD_BINDING_GRAD_LOG_SCALES, &b.g_log_scales->buffer(), Access::kWrite},
              {PBWD_BINDING_GRAD_QUATS, &b.g_quats->buffer(), Access::kWrite},
              {PBWD_BINDING_GRAD_OPACITY_LOGITS, &b.g_logits->buffer(), Access::kWrite},
              {PBWD_BINDING_GRAD_SH, &b.g_sh->buffer(), Access::kWrite}},
             view);
  return {&b.g_means->buffer(),  &b.g_log_scales->buffer(), &b.g_quats->buffer(),
          &b.g_logits->buffer(), &b.g_sh->buffer(),         &b.grad2d->buffer()};
}

GaussianGrads<float> Rasterizer::download_grads() const {
  if (!options_.parameter_gradients)
    throw std::logic_error("Rasterizer::download_grads: this rasterizer stores no parameter gradients");
  if (!last_gaussians_ || !buffers_->g_means)
    throw std::logic_error("Rasterizer::download_grads before backward");
  const Buffers& b = *buffers_;
  const size_t n = last_gaussians_->size();
  const size_t K = (last_gaussians_->sh_degree + 1) * (last_gaussians_->sh_degree + 1);
  GaussianGrads<float> out;
  out.means = b.g_means->download(0, 3 * n);
  out.log_scales = b.g_log_scales->download(0, 3 * n);
  out.quats = b.g_quats->download(0, 4 * n);
  out.opacity_logits = b.g_logits->download(0, n);
  out.sh = b.g_sh->download(0, n * K * channels_);
  const size_t stride = SPLAT_GRAD2D_FIXED + channels_;
  const std::vector<float> rows = b.grad2d->download(0, n * stride);
  out.means2d.resize(2 * n);
  for (size_t i = 0; i < n; ++i) {
    out.means2d[2 * i] = rows[i * stride];
    out.means2d[2 * i + 1] = rows[i * stride + 1];
  }
  return out;
}

}  // namespace litgs::kernels
