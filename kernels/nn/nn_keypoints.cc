#include "kernels/nn/nn_keypoints.h"

#include <stdexcept>
#include <string>

#include "kernels/elementwise.h"
#include "kernels/loss/loss_sum.h"
#include "kernels/nn/nn_shared.h"
#include "kernels/subgroup_kernel.h"

namespace litgs::kernels {
namespace {

using loss_detail::check_binding;

NnKeypointsParams params(uint32_t op, uint32_t channels, uint32_t h, uint32_t w, uint32_t count) {
  if (!h || !w) throw std::invalid_argument("KeypointKernel: an empty map");
  NnKeypointsParams p{};
  p.op = op;
  p.channels = channels;
  p.map_height = h;
  p.map_width = w;
  p.height = 8 * h;
  p.width = 8 * w;
  p.count = count;
  return p;
}

}  // namespace

KeypointKernel::KeypointKernel(engine::Context& context)
    : context_(&context),
      kernel_(
          make_kernel(context, "nn/nn_keypoints", NN_KEYPOINTS_BINDING_COUNT, sizeof(NnKeypointsParams))) {}

KeypointKernel::~KeypointKernel() = default;

void KeypointKernel::heatmap(engine::Sequence& s, const engine::Buffer& logits, const engine::Buffer& heat,
                             uint32_t h, uint32_t w) const {
  static const char* who = "KeypointKernel::heatmap";
  const NnKeypointsParams p = params(NN_KEYPOINTS_HEATMAP, 65, h, w, h * w);
  check_binding(who, "logits", logits, uint64_t{65} * h * w * sizeof(float));
  check_binding(who, "heat", heat, uint64_t{64} * h * w * sizeof(float));
  s.dispatch(*kernel_, elementwise_groups(*context_, p.count, who),
             {{NN_KEYPOINTS_BINDING_A, &logits, engine::Access::kRead},
              {NN_KEYPOINTS_BINDING_B, &logits, engine::Access::kRead},
              {NN_KEYPOINTS_BINDING_OUT, &heat, engine::Access::kWrite}},
             p);
}

void KeypointKernel::scores(engine::Sequence& s, const engine::Buffer& heat,
                            const engine::Buffer& reliability, const engine::Buffer& scores, uint32_t h,
                            uint32_t w, float threshold, uint32_t window) const {
  static const char* who = "KeypointKernel::scores";
  if (window % 2 == 0) throw std::invalid_argument(std::string(who) + ": the NMS window must be odd");
  NnKeypointsParams p = params(NN_KEYPOINTS_SCORES, 1, h, w, 64 * h * w);
  p.window = window;
  p.threshold = threshold;
  check_binding(who, "heat", heat, uint64_t{p.count} * sizeof(float));
  check_binding(who, "reliability", reliability, uint64_t{h} * w * sizeof(float));
  check_binding(who, "scores", scores, uint64_t{p.count} * sizeof(float));
  s.dispatch(*kernel_, elementwise_groups(*context_, p.count, who),
             {{NN_KEYPOINTS_BINDING_A, &heat, engine::Access::kRead},
              {NN_KEYPOINTS_BINDING_B, &reliability, engine::Access::kRead},
              {NN_KEYPOINTS_BINDING_OUT, &scores, engine::Access::kWrite}},
             p);
}

void KeypointKernel::normalize(engine::Sequence& s, const engine::Buffer& features, const engine::Buffer& out,
                               const MapShape& shape) const {
  static const char* who = "KeypointKernel::normalize";
  const NnKeypointsParams p =
      params(NN_KEYPOINTS_NORMALIZE, shape.channels, shape.height, shape.width, shape.height * shape.width);
  check_binding(who, "features", features, shape.elements() * sizeof(float));
  check_binding(who, "out", out, shape.elements() * sizeof(float));
  s.dispatch(*kernel_, elementwise_groups(*context_, p.count, who),
             {{NN_KEYPOINTS_BINDING_A, &features, engine::Access::kRead},
              {NN_KEYPOINTS_BINDING_B, &features, engine::Access::kRead},
              {NN_KEYPOINTS_BINDING_OUT, &out, engine::Access::kWrite}},
             p);
}

void KeypointKernel::descriptors(engine::Sequence& s, const engine::Buffer& normalized,
                                 const engine::Buffer& xy, const engine::Buffer& out, const MapShape& shape,
                                 uint32_t count) const {
  static const char* who = "KeypointKernel::descriptors";
  if (!shape.channels || shape.channels > NN_KEYPOINTS_MAX_CHANNELS)
    throw std::invalid_argument(std::string(who) + ": 1 to 64 channels, not " +
                                std::to_string(shape.channels));
  if (!count) return;
  const NnKeypointsParams p =
      params(NN_KEYPOINTS_DESCRIPTORS, shape.channels, shape.height, shape.width, count);
  check_binding(who, "normalized", normalized, shape.elements() * sizeof(float));
  check_binding(who, "xy", xy, uint64_t{2} * count * sizeof(float));
  check_binding(who, "out", out, uint64_t{count} * shape.channels * sizeof(float));
  s.dispatch(*kernel_, elementwise_groups(*context_, p.count, who),
             {{NN_KEYPOINTS_BINDING_A, &normalized, engine::Access::kRead},
              {NN_KEYPOINTS_BINDING_B, &xy, engine::Access::kRead},
              {NN_KEYPOINTS_BINDING_OUT, &out, engine::Access::kWrite}},
             p);
}

}  // namespace litgs::kernels
