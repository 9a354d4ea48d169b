#include "kernels/nn/nn_conv.h"

#include <stdexcept>
#include <string>

#include "kernels/elementwise.h"
#include "kernels/nn/nn_shared.h"
#include "kernels/subgroup_kernel.h"

namespace litgs::kernels {

void ConvShape::check() const {
  if (!in_channels || !in_height || !in_width || !out_channels || !kernel || !stride)
    throw std::invalid_argument("ConvShape: a zero size, kernel or stride");
  if (in_height + 2 * pad < kernel || in_width + 2 * pad < kernel)
    throw std::invalid_argument("ConvShape: the kernel is larger than the padded input");
}

Conv2dKernel::Conv2dKernel(engine::Context& context)
    : context_(&context),
      kernel_(make_kernel(context, "nn/nn_conv2d", NN_CONV_BINDING_COUNT, sizeof(NnConvParams))) {}

Conv2dKernel::~Conv2dKernel() = default;

void Conv2dKernel::record(engine::Sequence& s, const engine::Buffer& in, const engine::Buffer& weight,
                          const engine::Buffer& bias, const engine::Buffer& out, const ConvShape& c) const {
  static const char* who = "Conv2dKernel::record";
  c.check();
  const auto need = [](const char* name, const engine::Buffer& b, uint64_t floats) {
    if (b.size_bytes() < floats * sizeof(float))
      throw std::invalid_argument(std::string(who) + ": " + name + " holds " +
                                  std::to_string(b.size_bytes()) + " bytes, the shape needs " +
                                  std::to_string(floats * sizeof(float)));
  };
  need("in", in, uint64_t{c.in_channels} * c.in_height * c.in_width);
  need("weight", weight, uint64_t{c.out_channels} * c.in_channels * c.kernel * c.kernel);
  need("bias", bias, c.out_channels);
  need("out", out, c.out_elements());
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
  p.relu = c.relu ? 1u : 0u;
  p.count = static_cast<uint32_t>(c.out_elements());
  s.dispatch(*kernel_, elementwise_groups(*context_, p.count, who),
             {{NN_CONV_BINDING_IN, &in, engine::Access::kRead},
              {NN_CONV_BINDING_WEIGHT, &weight, engine::Access::kRead},
              {NN_CONV_BINDING_BIAS, &bias, engine::Access::kRead},
              {NN_CONV_BINDING_OUT, &out, engine::Access::kWrite}},
             p);
}

}  // namespace litgs::kernels
