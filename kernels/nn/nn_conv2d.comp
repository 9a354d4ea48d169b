#version 450
#extension GL_GOOGLE_include_directive : require
// ONNX Conv (group 1, dilation 1, zero padding) with an optional ReLU or sigmoid: an invocation computes
// NN_CONV_OUTPUTS output channels at one pixel, so that each input value is loaded once for all of them,
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
  const uint o0 = (e / (p.out_width * p.out_height)) * NN_CONV_OUTPUTS;
  const uint outputs = min(NN_CONV_OUTPUTS, p.out_channels - o0);
  const int y0 = int(oy * p.stride) - int(p.pad), x0 = int(ox * p.stride) - int(p.pad);
  const uint taps_per_output = p.in_channels * p.kernel * p.kernel;
  float sum[NN_CONV_OUTPUTS];
  for (uint j = 0u; j < NN_CONV_OUTPUTS; ++j) sum[j] = j < outputs ? b[o0 + j] : 0.0;
  for (uint c = 0u; c < p.in_channels; ++c) {
    const uint plane = c * p.in_height * p.in_width;
    for (uint ky = 0u; ky < p.kernel; ++ky) {
      const int sy = y0 + int(ky);
      if (sy < 0 || sy >= int(p.in_height)) continue;
      for (uint kx = 0u; kx < p.kernel; ++kx) {
        const int sx = x0 + int(kx);
        if (sx < 0 || sx >= int(p.in_width)) continue;
        const float v = x[plane + uint(sy) * p.in_width + uint(sx)];
        const uint tap = (c * p.kernel + ky) * p.kernel + kx;
        // A constant bound, so that the compiler unrolls it and keeps the sums in registers.
        for (uint j = 0u; j < NN_CONV_OUTPUTS; ++j)
          if (j < outputs) sum[j] += w[(o0 + j) * taps_per_output + tap] * v;
      }
    }
  }
  const uint plane_out = p.out_height * p.out_width;
  for (uint j = 0u; j < outputs; ++j) {
    float s = sum[j];
    if (p.activation == NN_ACTIVATION_RELU) s = max(s, 0.0);
    if (p.activation == NN_ACTIVATION_SIGMOID) s = 1.0 / (1.0 + exp(-s));
    y[(o0 + j) * plane_out + oy * p.out_width + ox] = s;
  }
}
