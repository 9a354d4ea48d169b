// Network convolutions on the device (nn_conv2d.comp): ONNX Conv with group 1, dilation 1 and zero padding,
// optionally followed by ReLU. Its CPU double reference is kernels/nn/nn_reference.h's conv2d.
#pragma once

#include <cstdint>
#include <memory>

#include "engine/buffer.h"
#include "engine/context.h"
#include "engine/kernel.h"
#include "engine/sequence.h"

namespace litgs::kernels {

struct ConvShape {
  uint32_t in_channels = 0, in_height = 0, in_width = 0;
  uint32_t out_channels = 0, kernel = 1, stride = 1, pad = 0;
  bool relu = false;
  uint32_t out_height() const { return (in_height + 2 * pad - kernel) / stride + 1; }
  uint32_t out_width() const { return (in_width + 2 * pad - kernel) / stride + 1; }
  uint64_t out_elements() const { return uint64_t{out_channels} * out_height() * out_width(); }
  void check() const;  // std::invalid_argument naming the bad field
};

class Conv2dKernel {
 public:
  explicit Conv2dKernel(engine::Context& context);
  ~Conv2dKernel();
  // Records out = conv(in) (+ ReLU). Buffers too small for the shape are std::invalid_argument.
  void record(engine::Sequence& sequence, const engine::Buffer& in, const engine::Buffer& weight,
              const engine::Buffer& bias, const engine::Buffer& out, const ConvShape& shape) const;

 private:
  engine::Context* context_;
  std::unique_ptr<engine::Kernel> kernel_;
};

}  // namespace litgs::kernels
