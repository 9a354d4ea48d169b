#version 450
#extension GL_GOOGLE_include_directive : require
#extension GL_EXT_control_flow_attributes : require
// ONNX Conv (group 1, dilation 1, zero padding) with an optional ReLU or sigmoid: an invocation computes
// NN_CONV_OUTPUTS output channels at NN_CONV_PIXELS pixels of one row, so that each weight loaded serves all
// the pixels and each input value all the channels (a register tile, as a GEMM's; larger tiles spilled on
// lavapipe, docs/experiments.md). Each output is summed in the order of kernels/nn/nn_reference.cc's conv2d:
// channel, kernel row, kernel column (a tap in the padding adds zero there, where the reference skips it).
#include "limits.h"
#include "nn/nn_shared.h"

layout(local_size_x = NN_CONV_GROUP_SIZE) in;

// The input and the weights are uniform texel buffers (nn_shared.h): on CPU drivers a texel fetch is one
// vector gather, a storage-buffer load at a per-lane index a loop over the lanes. The weights are packed
// in fours of output channels (pack_conv_weights), so that one four-float fetch serves four channels.
layout(binding = NN_CONV_BINDING_IN) uniform samplerBuffer x;
layout(binding = NN_CONV_BINDING_WEIGHT) uniform samplerBuffer w;
layout(std430, binding = NN_CONV_BINDING_BIAS) readonly buffer Bias { float b[]; };
layout(std430, binding = NN_CONV_BINDING_OUT) writeonly buffer Out { float y[]; };
layout(push_constant) uniform Push { NnConvParams p; };

void main() {
  // The channel block comes from the workgroup alone: the weights' addresses are then the same in every
  // invocation of a group (uniform loads on a GPU).
  const uint tile = gl_WorkGroupID.x * NN_CONV_GROUP_SIZE + gl_LocalInvocationID.x;
  if (tile >= p.count) return;
  // NN_CONV_LANES neighbouring invocations share a run of NN_CONV_LANES x NN_CONV_PIXELS pixels of a row,
  // interleaved (pixel q of lane l: l + q NN_CONV_LANES), so that their loads of one tap are contiguous
  // (coalesced on a GPU, neighbouring cache lines on lavapipe).
  const uint runs_x = (p.out_width + NN_CONV_RUN - 1u) / NN_CONV_RUN;
  const uint run = tile / NN_CONV_LANES;
  const uint ox0 = (run % runs_x) * NN_CONV_RUN + tile % NN_CONV_LANES;
  const uint oy = run / runs_x;
  const uint o0 = gl_WorkGroupID.y * NN_CONV_OUTPUTS;
  const uint outputs = min(NN_CONV_OUTPUTS, p.out_channels - o0);
  const int y0 = int(oy * p.stride) - int(p.pad), x0 = int(ox0 * p.stride) - int(p.pad);
  const uint taps_per_output = p.in_channels * p.kernel * p.kernel;
  const uint fours = (p.out_channels + 3u) / 4u;  // the packed weights' groups of four output channels
  // Constant bounds throughout, so that the compiler unrolls them and keeps the tile in registers.
  float sum[NN_CONV_OUTPUTS][NN_CONV_PIXELS];
  [[unroll]] for (uint j = 0u; j < NN_CONV_OUTPUTS; ++j) {
    const float bias = b[min(o0 + j, p.out_channels - 1u)];
    [[unroll]] for (uint q = 0u; q < NN_CONV_PIXELS; ++q) sum[j][q] = bias;
  }
  for (uint c = 0u; c < p.in_channels; ++c) {
    const uint plane = c * p.in_height * p.in_width;
    for (uint ky = 0u; ky < p.kernel; ++ky) {
      const int sy = y0 + int(ky);
      if (sy < 0 || sy >= int(p.in_height)) continue;
      const uint row = plane + uint(sy) * p.in_width;
      for (uint kx = 0u; kx < p.kernel; ++kx) {
        float v[NN_CONV_PIXELS];
        [[unroll]] for (uint q = 0u; q < NN_CONV_PIXELS; ++q) {
          const int sx = x0 + int(q * NN_CONV_LANES * p.stride + kx);
          v[q] = (sx >= 0 && sx < int(p.in_width)) ? texelFetch(x, int(row) + sx).x : 0.0;
        }
        const uint tap = (c * p.kernel + ky) * p.kernel + kx;
        // A block past the last four channels reads the last four's weights again and never writes them
        // (the packing's zeros fill the last four).
        [[unroll]] for (uint f = 0u; f < NN_CONV_OUTPUTS / 4u; ++f) {
          const vec4 w4 = texelFetch(w, int(min(o0 / 4u + f, fours - 1u) * taps_per_output + tap));
          [[unroll]] for (uint q = 0u; q < NN_CONV_PIXELS; ++q) {
            sum[4u * f][q] += w4.x * v[q];
            sum[4u * f + 1u][q] += w4.y * v[q];
            sum[4u * f + 2u][q] += w4.z * v[q];
            sum[4u * f + 3u][q] += w4.w * v[q];
          }
        }
      }
    }
  }
  const uint plane_out = p.out_height * p.out_width;
  for (uint j = 0u; j < outputs; ++j) {
    for (uint q = 0u; q < NN_CONV_PIXELS; ++q) {
      const uint ox = ox0 + q * NN_CONV_LANES;
      if (ox >= p.out_width) break;
      float s = sum[j][q];
      if (p.activation == NN_ACTIVATION_RELU) s = max(s, 0.0);
      if (p.activation == NN_ACTIVATION_SIGMOID) s = 1.0 / (1.0 + exp(-s));
      y[(o0 + j) * plane_out + oy * p.out_width + ox] = s;
    }
  }
}
