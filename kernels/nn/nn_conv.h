// Network convolutions on the device (nn_conv2d.comp): ONNX Conv with group 1, dilation 1 and zero padding,
// optionally followed by ReLU or a sigmoid and a residual add; and the other operations of a network's
// feature maps (nn_map.comp: add, average pool, bilinear resize, unfold, the add of a resized map). Its CPU
// double reference is kernels/nn/nn_reference.h's conv2d.
#pragma once

#include <cstdint>
#include <memory>
#include <vector>

#include "engine/buffer.h"
#include "engine/context.h"
#include "engine/kernel.h"
#include "engine/sequence.h"

namespace litgs::kernels {

struct ConvShape {
  uint32_t in_channels = 0, in_height = 0, in_width = 0;
  uint32_t out_channels = 0, kernel = 1, stride = 1, pad = 0;
  uint32_t activation = 0;  // NN_ACTIVATION_NONE, _RELU or _SIGMOID (nn_shared.h)
  uint32_t out_height() const { return (in_height + 2 * pad - kernel) / stride + 1; }
  uint32_t out_width() const { return (in_width + 2 * pad - kernel) / stride + 1; }
  uint64_t out_elements() const { return uint64_t{out_channels} * out_height() * out_width(); }
  void check() const;  // std::invalid_argument naming the bad field
};

// ONNX Conv weights [out_channels][in_channels][kernel][kernel] as nn_conv2d.comp reads them:
// [ceil(out_channels / 4)][in_channels][kernel][kernel][4], four output channels per tap side by side (zeros
// past the last channel), so that one four-float texel fetch serves four channels. std::invalid_argument
// when `weight` does not hold out_channels * in_channels * kernel * kernel values.
std::vector<float> pack_conv_weights(const std::vector<float>& weight, uint32_t out_channels,
                                     uint32_t in_channels, uint32_t kernel);
// The floats pack_conv_weights returns: 4 ceil(out_channels / 4) in_channels kernel^2.
uint64_t packed_conv_weight_floats(uint32_t out_channels, uint32_t in_channels, uint32_t kernel);

// A feature map's shape on the device: [channels][height][width] floats.
struct MapShape {
  uint32_t channels = 0, height = 0, width = 0;
  uint64_t elements() const { return uint64_t{channels} * height * width; }
};

class MapKernel {
 public:
  explicit MapKernel(engine::Context& context);
  ~MapKernel();
  // out = a + b, both of `shape`.
  void add(engine::Sequence& s, const engine::Buffer& a, const engine::Buffer& b, const engine::Buffer& out,
           const MapShape& shape) const;
  // out = k x k averages of a every k pixels; returns the output's shape.
  MapShape average_pool(engine::Sequence& s, const engine::Buffer& a, const engine::Buffer& out,
                        const MapShape& in, uint32_t k) const;
  // out = a resized to height x width (ONNX Resize, linear, half_pixel).
  MapShape resize(engine::Sequence& s, const engine::Buffer& a, const engine::Buffer& out, const MapShape& in,
                  uint32_t height, uint32_t width) const;
  // out = b + a resized to b's height and width (b and out of `shape`, a of `in`: as many channels).
  void add_resized(engine::Sequence& s, const engine::Buffer& a, const engine::Buffer& b,
                   const engine::Buffer& out, const MapShape& in, const MapShape& shape) const;
  // A one-channel image's k x k blocks as k * k channels (XFeat's _unfold2d).
  MapShape unfold(engine::Sequence& s, const engine::Buffer& a, const engine::Buffer& out, const MapShape& in,
                  uint32_t k) const;

 private:
  void dispatch(engine::Sequence& s, uint32_t op, const engine::Buffer& a, const engine::Buffer& b,
                const engine::Buffer& out, const MapShape& in, const MapShape& out_shape, uint32_t k) const;
  engine::Context* context_;
  std::unique_ptr<engine::Kernel> kernel_;
};

class Conv2dKernel {
 public:
  explicit Conv2dKernel(engine::Context& context);
  ~Conv2dKernel();
  // Records out = conv(in) (+ the activation) (+ residual, a map of out's shape, when given); `weight` holds
  // pack_conv_weights' layout. Buffers too small for the shape are std::invalid_argument.
  void record(engine::Sequence& sequence, const engine::Buffer& in, const engine::Buffer& weight,
              const engine::Buffer& bias, const engine::Buffer& out, const ConvShape& shape,
              const engine::Buffer* residual = nullptr) const;

 private:
  engine::Context* context_;
  std::unique_ptr<engine::Kernel> kernel_;
};

}  // namespace litgs::kernels
