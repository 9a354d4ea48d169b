#include "kernels/nn/nn_conv.h"

#include <stdexcept>
#include <string>

#include "kernels/elementwise.h"
#include "kernels/loss/loss_sum.h"
#include "kernels/nn/nn_shared.h"
#include "kernels/subgroup_kernel.h"

namespace litgs::kernels {

// The binding-size check every kernel wrapper shares (kernels/loss/loss_sum.h).
using loss_detail::check_binding;

void ConvShape::check() const {
  if (!in_channels || !in_height || !in_width || !out_channels || !kernel || !stride)
    throw std::invalid_argument("ConvShape: a zero size, kernel or stride");
  if (activation > NN_ACTIVATION_SIGMOID) throw std::invalid_argument("ConvShape: unknown activation");
  if (in_height + 2 * pad < kernel || in_width + 2 * pad < kernel)
    throw std::invalid_argument("ConvShape: the kernel is larger than the padded input");
}

uint64_t packed_conv_weight_floats(uint32_t out_channels, uint32_t in_channels, uint32_t kernel) {
  return (uint64_t{out_channels} + 3) / 4 * 4 * in_channels * kernel * kernel;
}

std::vector<float> pack_conv_weights(const std::vector<float>& weight, uint32_t out_channels,
                                     uint32_t in_channels, uint32_t kernel) {
  const size_t taps = size_t{in_channels} * kernel * kernel;
  if (weight.size() != size_t{out_channels} * taps)
    throw std::invalid_argument("pack_conv_weights: " + std::to_string(weight.size()) + " weights for " +
                                std::to_string(out_channels) + " x " + std::to_string(in_channels) + " x " +
                                std::to_string(kernel) + " x " + std::to_string(kernel));
  std::vector<float> packed(packed_conv_weight_floats(out_channels, in_channels, kernel), 0.0f);
  for (size_t o = 0; o < out_channels; ++o)
    for (size_t t = 0; t < taps; ++t) packed[((o / 4) * taps + t) * 4 + o % 4] = weight[o * taps + t];
  return packed;
}

Conv2dKernel::Conv2dKernel(engine::Context& context)
    : context_(&context),
      // The input and the weights as texels (nn_shared.h), and the input again as four-float texels of its
      // rows (the 1x1 and 3x3 row paths of nn_conv2d.comp).
      kernel_(make_kernel(context, "nn/nn_conv2d", NN_CONV_BINDING_COUNT, sizeof(NnConvParams), {},
                          {{NN_CONV_BINDING_IN, VK_FORMAT_R32_SFLOAT},
                           {NN_CONV_BINDING_WEIGHT, VK_FORMAT_R32G32B32A32_SFLOAT},
                           {NN_CONV_BINDING_IN4, VK_FORMAT_R32G32B32A32_SFLOAT}})) {}

Conv2dKernel::~Conv2dKernel() = default;

void Conv2dKernel::record(engine::Sequence& s, const engine::Buffer& in, const engine::Buffer& weight,
                          const engine::Buffer& bias, const engine::Buffer& out, const ConvShape& c,
                          const engine::Buffer* residual) const {
  static const char* who = "Conv2dKernel::record";
  c.check();
  check_binding(who, "in", in, uint64_t{c.in_channels} * c.in_height * c.in_width * sizeof(float));
  check_binding(who, "weight (packed)", weight,
                packed_conv_weight_floats(c.out_channels, c.in_channels, c.kernel) * sizeof(float));
  check_binding(who, "bias", bias, uint64_t{c.out_channels} * sizeof(float));
  check_binding(who, "out", out, c.out_elements() * sizeof(float));
  if (residual) check_binding(who, "residual", *residual, c.out_elements() * sizeof(float));
  NnConvParams p{};
  p.in_channels = c.in_channels;
  p.in_height = c.in_height;
  p.in_width = c.in_width;
  p.out_channels = c.out_channels;
  p.out_height = c.out_height();
  p.out_width = c.out_width();
  p.kernel = c.kernel;
  p.stride = c.stride;
  p.pad = c.pad;
  p.activation = c.activation;
  p.has_residual = residual != nullptr;
  const uint64_t tiles =
      uint64_t{c.out_height()} * ((c.out_width() + NN_CONV_RUN - 1) / NN_CONV_RUN) * NN_CONV_LANES;
  const uint64_t groups_x = (tiles + NN_CONV_GROUP_SIZE - 1) / NN_CONV_GROUP_SIZE;
  const uint32_t channel_blocks = (c.out_channels + NN_CONV_OUTPUTS - 1) / NN_CONV_OUTPUTS;
  const uint32_t* limit = context_->info().max_compute_workgroup_count;
  if (groups_x > limit[0] || channel_blocks > limit[1])
    throw std::length_error(std::string(who) + ": " + std::to_string(groups_x) + " x " +
                            std::to_string(channel_blocks) + " workgroups exceed the device's grid");
  p.count = static_cast<uint32_t>(tiles);
  s.dispatch(*kernel_, engine::Groups{static_cast<uint32_t>(groups_x), channel_blocks, 1},
             {{NN_CONV_BINDING_IN, &in, engine::Access::kRead},
              {NN_CONV_BINDING_WEIGHT, &weight, engine::Access::kRead},
              {NN_CONV_BINDING_BIAS, &bias, engine::Access::kRead},
              {NN_CONV_BINDING_OUT, &out, engine::Access::kWrite},
              {NN_CONV_BINDING_IN4, &in, engine::Access::kRead},
              {NN_CONV_BINDING_RESIDUAL, residual ? residual : &bias, engine::Access::kRead}},
             p);
}

MapKernel::MapKernel(engine::Context& context)
    : context_(&context),
      // Both operands as texels (nn_map.comp).
      kernel_(make_kernel(
          context, "nn/nn_map", NN_MAP_BINDING_COUNT, sizeof(NnMapParams), {},
          {{NN_MAP_BINDING_A, VK_FORMAT_R32_SFLOAT}, {NN_MAP_BINDING_B, VK_FORMAT_R32_SFLOAT}})) {}

MapKernel::~MapKernel() = default;

void MapKernel::dispatch(engine::Sequence& s, uint32_t op, const engine::Buffer& a, const engine::Buffer& b,
                         const engine::Buffer& out, const MapShape& in, const MapShape& o, uint32_t k) const {
  static const char* who = "MapKernel";
  if (!in.elements() || !o.elements())
    throw std::invalid_argument(std::string(who) + ": an empty feature map");
  check_binding(who, "a", a, in.elements() * sizeof(float));
  const uint64_t b_elements = op == NN_MAP_ADD ? in.elements() : op == NN_MAP_ADD_RESIZED ? o.elements() : 0;
  check_binding(who, "b", b, b_elements * sizeof(float));
  check_binding(who, "out", out, o.elements() * sizeof(float));
  NnMapParams p{};
  p.op = op;
  p.channels = in.channels;
  p.in_height = in.height;
  p.in_width = in.width;
  p.out_channels = o.channels;
  p.out_height = o.height;
  p.out_width = o.width;
  p.k = k;
  p.count = static_cast<uint32_t>(o.elements());
  s.dispatch(*kernel_, elementwise_groups(*context_, p.count, who),
             {{NN_MAP_BINDING_A, &a, engine::Access::kRead},
              {NN_MAP_BINDING_B, &b, engine::Access::kRead},
              {NN_MAP_BINDING_OUT, &out, engine::Access::kWrite}},
             p);
}

void MapKernel::add(engine::Sequence& s, const engine::Buffer& a, const engine::Buffer& b,
                    const engine::Buffer& out, const MapShape& shape) const {
  dispatch(s, NN_MAP_ADD, a, b, out, shape, shape, 1);
}

MapShape MapKernel::average_pool(engine::Sequence& s, const engine::Buffer& a, const engine::Buffer& out,
                                 const MapShape& in, uint32_t k) const {
  if (!k || in.height < k || in.width < k)
    throw std::invalid_argument("MapKernel::average_pool: window " + std::to_string(k));
  const MapShape o{in.channels, in.height / k, in.width / k};
  dispatch(s, NN_MAP_AVERAGE_POOL, a, a, out, in, o, k);
  return o;
}

MapShape MapKernel::resize(engine::Sequence& s, const engine::Buffer& a, const engine::Buffer& out,
                           const MapShape& in, uint32_t height, uint32_t width) const {
  const MapShape o{in.channels, height, width};
  dispatch(s, NN_MAP_RESIZE, a, a, out, in, o, 1);
  return o;
}

void MapKernel::add_resized(engine::Sequence& s, const engine::Buffer& a, const engine::Buffer& b,
                            const engine::Buffer& out, const MapShape& in, const MapShape& shape) const {
  if (in.channels != shape.channels)
    throw std::invalid_argument("MapKernel::add_resized: " + std::to_string(in.channels) +
                                " channels resized onto " + std::to_string(shape.channels));
  dispatch(s, NN_MAP_ADD_RESIZED, a, b, out, in, shape, 1);
}

MapShape MapKernel::unfold(engine::Sequence& s, const engine::Buffer& a, const engine::Buffer& out,
                           const MapShape& in, uint32_t k) const {
  if (in.channels != 1 || !k || in.height % k || in.width % k)
    throw std::invalid_argument("MapKernel::unfold: a one-channel image whose sides are multiples of " +
                                std::to_string(k));
  const MapShape o{k * k, in.height / k, in.width / k};
  dispatch(s, NN_MAP_UNFOLD, a, a, out, in, o, k);
  return o;
}

}  // namespace litgs::kernels
