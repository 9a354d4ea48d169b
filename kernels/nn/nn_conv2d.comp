#version 450
#extension GL_GOOGLE_include_directive : require
// ONNX Conv (group 1, dilation 1, zero padding) with an optional ReLU or sigmoid, one output element per invocation,
// summed in the same order as kernels/nn/nn_reference.cc's conv2d: channel, kernel row, kernel column.
#include "limits.h"
#include "nn/nn_shared.h"
#include "elementwise.glsl"

layout(std430, binding = NN_CONV_BINDING_IN) readonly buffer In { float x[]; };
layout(std430, binding = NN_CONV_BINDING_WEIGHT) readonly buffer Weight { float w[]; };
layout(std430, binding = NN_CONV_BINDING_BIAS) readonly buffer Bias { float b[]; };
layout(std430, binding = NN_CONV_BINDING_OUT) writeonly buffer Out { float y[]; };
layout(push_constant) uniform Push { NnConvParams p; };

void main() {
  const uint e = elementwise_index();
  if (e >= p.count) return;
  const uint ox = e % p.out_width;
  const uint oy = (e / p.out_width) % p.out_height;
  const uint o = e / (p.out_width * p.out_height);
  const int y0 = int(oy * p.stride) - int(p.pad), x0 = int(ox * p.stride) - int(p.pad);
  float sum = b[o];
  for (uint c = 0u; c < p.in_channels; ++c) {
    const uint plane = c * p.in_height * p.in_width;
    const uint taps = (o * p.in_channels + c) * p.kernel * p.kernel;
    for (uint ky = 0u; ky < p.kernel; ++ky) {
      const int sy = y0 + int(ky);
      if (sy < 0 || sy >= int(p.in_height)) continue;
      for (uint kx = 0u; kx < p.kernel; ++kx) {
        const int sx = x0 + int(kx);
        if (sx < 0 || sx >= int(p.in_width)) continue;
        sum += w[taps + ky * p.kernel + kx] * x[plane + uint(sy) * p.in_width + uint(sx)];
      }
    }
  }
  if (p.activation == NN_ACTIVATION_RELU) sum = max(sum, 0.0);
  if (p.activation == NN_ACTIVATION_SIGMOID) sum = 1.0 / (1.0 + exp(-sum));
  y[e] = sum;
}
