#include "kernels/level/level_model.h"

#include <stdexcept>
#include <string>

#include "kernels/device_growth.h"
#include "kernels/elementwise.h"
#include "kernels/limits.h"
#include "kernels/loss/loss_sum.h"
#include "kernels/subgroup_kernel.h"

namespace litgs::kernels {

using engine::Access;
using loss_detail::check_binding;

namespace {
uint64_t level_blocks(uint64_t elements) {
  return std::max<uint64_t>(1, (elements + LEVEL_ROWS_PER_GROUP - 1) / LEVEL_ROWS_PER_GROUP);
}
}  // namespace

LevelParams LevelGeometry::params(uint32_t frame, uint32_t frames, bool vignetting) const {
  LevelParams p{};
  p.width = width;
  p.height = height;
  p.count = channels * width * height;
  p.frame = frame;
  p.cx = cx;
  p.cy = cy;
  p.inv_r2_norm = static_cast<float>(1.0 / (0.25 * width * width + 0.25 * height * height));
  p.vignetting = vignetting ? 1u : 0u;
  p.frames = frames;
  return p;
}

std::vector<float> LevelModel::identity_state(const std::vector<bool>& trained) {
  std::vector<float> s((trained.size() + 1) * LEVEL_STRIDE, 0.0f);
  for (size_t f = 0; f < trained.size(); ++f) s[f * LEVEL_STRIDE + LEVEL_TRAINED] = trained[f] ? 1.0f : 0.0f;
  return s;
}

LevelModel::LevelModel(engine::Context& context, const std::vector<bool>& trained, bool vignetting)
    : context_(&context),
      frames_(static_cast<uint32_t>(trained.size())),
      vignetting_(vignetting),
      state_(context, "level: state", (trained.size() + 1) * LEVEL_STRIDE) {
  if (trained.empty()) throw std::invalid_argument("LevelModel: no frames");
  // level_step walks the frames 256 at a time: stay within lavapipe's loop budget (limits.h).
  if (trained.size() > size_t{256} * MAX_BATCHES_PER_WORKGROUP)
    throw std::length_error("LevelModel: " + std::to_string(trained.size()) +
                            " frames exceed the step's capacity");
  apply_ = make_kernel(context, "level/level_apply", LEVEL_APPLY_BINDING_COUNT, sizeof(LevelParams));
  backward_ = make_kernel(context, "level/level_backward", LEVEL_BACKWARD_BINDING_COUNT, sizeof(LevelParams));
  step_ = make_kernel(context, "level/level_step", LEVEL_STEP_BINDING_COUNT, sizeof(LevelStepParams));
  upload_state(identity_state(trained));
}

LevelModel::~LevelModel() = default;

void LevelModel::reserve(uint64_t elements) {
  grow(*context_, leveled_, elements, "level: leveled image");
  grow(*context_, grad_leveled_, elements, "level: leveled image gradient");
  grow(*context_, block_sums_, 4 * level_blocks(elements), "level: block sums");
}

namespace {
void check_geometry(const char* who, const LevelGeometry& g, uint32_t frame, uint32_t frames) {
  if (g.width == 0 || g.height == 0 || g.channels == 0)
    throw std::invalid_argument(std::string(who) + ": empty image");
  if (uint64_t{g.channels} * g.width * g.height > uint64_t{256} * LEVEL_ROWS_PER_GROUP * 4096)
    throw std::length_error(std::string(who) + ": image too large for the level reduction");
  if (frame >= frames)
    throw std::invalid_argument(std::string(who) + ": frame " + std::to_string(frame) + " of " +
                                std::to_string(frames));
}
}  // namespace

void LevelModel::record_apply(engine::Sequence& s, const engine::Buffer& image, uint32_t frame,
                              const LevelGeometry& geometry) {
  static const char* who = "LevelModel::record_apply";
  check_geometry(who, geometry, frame, frames_);
  const LevelParams p = geometry.params(frame, frames_, vignetting_);
  reserve(p.count);
  check_binding(who, "image", image, uint64_t{p.count} * sizeof(float));
  s.dispatch(*apply_, elementwise_groups(*context_, p.count, who),
             {{LEVEL_APPLY_BINDING_IMAGE, &image, Access::kRead},
              {LEVEL_APPLY_BINDING_STATE, &state_.buffer(), Access::kRead},
              {LEVEL_APPLY_BINDING_OUT, &leveled_->buffer(), Access::kWrite}},
             p);
}

void LevelModel::record_backward_step(engine::Sequence& s, const engine::Buffer& image,
                                      const LevelGeometry& geometry, const LevelStep& step,
                                      const engine::Buffer& grad_image) {
  static const char* who = "LevelModel::record_backward_step";
  check_geometry(who, geometry, step.frame, frames_);
  for (int n : {step.prev, step.next})
    if (n >= static_cast<int>(frames_))
      throw std::invalid_argument(std::string(who) + ": neighbour " + std::to_string(n) + " of " +
                                  std::to_string(frames_) + " frames");
  const LevelParams p = geometry.params(step.frame, frames_, vignetting_);
  reserve(p.count);
  const uint64_t bytes = uint64_t{p.count} * sizeof(float);
  check_binding(who, "image", image, bytes);
  check_binding(who, "grad_image", grad_image, bytes);
  const uint64_t blocks = level_blocks(p.count);
  s.dispatch(*backward_, {static_cast<uint32_t>(blocks)},
             {{LEVEL_BACKWARD_BINDING_IMAGE, &image, Access::kRead},
              {LEVEL_BACKWARD_BINDING_GRAD_LEVELED, &grad_leveled_->buffer(), Access::kRead},
              {LEVEL_BACKWARD_BINDING_STATE, &state_.buffer(), Access::kRead},
              {LEVEL_BACKWARD_BINDING_GRAD_IMAGE, &grad_image, Access::kWrite},
              {LEVEL_BACKWARD_BINDING_SUMS, &block_sums_->buffer(), Access::kWrite}},
             p);
  LevelStepParams q{};
  q.blocks = static_cast<uint32_t>(blocks);
  q.frame = step.frame;
  q.prev = step.prev;
  q.next = step.next;
  q.center = step.center ? 1u : 0u;
  q.vignetting = vignetting_ ? 1u : 0u;
  q.lr_log_gain = step.lr_log_gain;
  q.lr_offset = step.lr_offset;
  q.lr_vignetting = step.lr_vignetting;
  q.lambda_identity = step.lambda_identity;
  q.lambda_smooth = step.lambda_smooth;
  q.beta1 = step.beta1;
  q.beta2 = step.beta2;
  q.eps = step.eps;
  q.frames = frames_;
  s.dispatch(*step_, {1},
             {{LEVEL_STEP_BINDING_SUMS, &block_sums_->buffer(), Access::kRead},
              {LEVEL_STEP_BINDING_STATE, &state_.buffer(), Access::kReadWrite}},
             q);
}

std::vector<float> LevelModel::download_state() const {
  return state_.download();
}

void LevelModel::upload_state(const std::vector<float>& state) {
  if (state.size() != state_.size())
    throw std::invalid_argument("LevelModel: a level state of " + std::to_string(state.size()) +
                                " values for " + std::to_string(frames_) + " frames (needs " +
                                std::to_string(state_.size()) + ")");
  state_.upload(state);
}

LevelValues level_values(const std::vector<float>& state, uint32_t frame, bool vignetting) {
  const size_t frames = state.size() / LEVEL_STRIDE - 1;
  if (state.size() % LEVEL_STRIDE != 0 || frame >= frames)
    throw std::invalid_argument("level_values: frame " + std::to_string(frame) + " of a state of " +
                                std::to_string(state.size()) + " values");
  LevelValues v;
  v.log_gain = state[size_t{frame} * LEVEL_STRIDE];
  v.offset = state[size_t{frame} * LEVEL_STRIDE + 1];
  if (vignetting) {
    v.k1 = state[frames * LEVEL_STRIDE];
    v.k2 = state[frames * LEVEL_STRIDE + 1];
  }
  return v;
}

}  // namespace litgs::kernels
