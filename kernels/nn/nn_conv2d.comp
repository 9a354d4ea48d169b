#version 450
#extension GL_GOOGLE_include_directive : require
#extension GL_EXT_control_flow_attributes : require
// ONNX Conv (group 1, dilation 1, zero padding) with an optional ReLU or sigmoid, then optionally a residual
// map added (a following ONNX Add of two maps, without a pass of its own): an invocation computes
// NN_CONV_OUTPUTS output channels at NN_CONV_PIXELS pixels of one row, so that each weight loaded serves all
// the pixels and each input value all the channels (a register tile, as a GEMM's; larger tiles spilled on
// lavapipe, docs/experiments.md). Each output is summed in the order of kernels/nn/nn_reference.cc's conv2d:
// channel, kernel row, kernel column (a tap in the padding adds zero there, where the reference skips it).
#include "limits.h"
#include "nn/nn_shared.h"

layout(local_size_x = NN_CONV_GROUP_SIZE) in;

// The input and the weights are uniform texel buffers (nn_shared.h): on CPU drivers a one-float texel fetch
// is one vector gather, a storage-buffer load at a per-lane index a loop over the lanes, and a four-float
// fetch one 16-byte load per lane. The weights are packed in fours of output channels (pack_conv_weights),
// so that one four-float fetch serves four channels; the input is bound twice, as one-float texels and as
// four-float texels of its rows.
layout(binding = NN_CONV_BINDING_IN) uniform samplerBuffer x;
layout(binding = NN_CONV_BINDING_WEIGHT) uniform samplerBuffer w;
layout(binding = NN_CONV_BINDING_IN4) uniform samplerBuffer x4;
layout(std430, binding = NN_CONV_BINDING_BIAS) readonly buffer Bias { float b[]; };
layout(std430, binding = NN_CONV_BINDING_OUT) writeonly buffer Out { float y[]; };
layout(std430, binding = NN_CONV_BINDING_RESIDUAL) readonly buffer Residual { float r[]; };
layout(push_constant) uniform Push { NnConvParams p; };

#if NN_CONV_PIXELS != 4
#error "the row paths read four pixels of a row as one four-float texel"
#endif

// One tap into the register tile: the block's group F of four output channels at the tile's pixels, with
// V[q] the input under pixel q and W4 the tap's weights of those four channels.
#define NN_CONV_ACCUMULATE(F, W4, V)                                \
  [[unroll]] for (uint q = 0u; q < NN_CONV_PIXELS; ++q) {           \
    sum[4u * (F)][q] += (W4).x * (V)[q];                            \
    sum[4u * (F) + 1u][q] += (W4).y * (V)[q];                       \
    sum[4u * (F) + 2u][q] += (W4).z * (V)[q];                       \
    sum[4u * (F) + 3u][q] += (W4).w * (V)[q];                       \
  }

void main() {
  // The channel block comes from the workgroup alone: the weights' addresses are then the same in every
  // invocation of a group (uniform loads on a GPU).
  const uint tile = gl_WorkGroupID.x * NN_CONV_GROUP_SIZE + gl_LocalInvocationID.x;
  if (tile >= p.count) return;
  // NN_CONV_LANES neighbouring invocations share a run of NN_CONV_LANES x NN_CONV_PIXELS pixels of a row.
  // On the generic path they interleave (pixel q of lane l: l + q NN_CONV_LANES), so that their loads of one
  // tap are contiguous (coalesced on a GPU, neighbouring cache lines on lavapipe); on the row paths each
  // takes four contiguous pixels (4 l + q), one texel.
  const uint runs_x = (p.out_width + NN_CONV_RUN - 1u) / NN_CONV_RUN;
  const uint run = tile / NN_CONV_LANES, lane = tile % NN_CONV_LANES;
  const uint run_x = (run % runs_x) * NN_CONV_RUN;
  // A 1x1 convolution of stride 1, and a 3x3 one of padding 1 and stride 1 or 2, read each row of input as
  // four-float texels: the taps of an invocation's four pixels in one input row lie in three texels (one,
  // for 1x1). Three fetches per input row serve nine taps, where the generic path gathers 12 times. Every
  // XFeat layer takes one of them when the image's width is a multiple of 128 (a 640-wide frame).
  const bool rows4 = p.in_width % 4u == 0u && p.out_width % 4u == 0u &&
                     ((p.kernel == 1u && p.stride == 1u && p.pad == 0u) ||
                      (p.kernel == 3u && p.pad == 1u && (p.stride == 1u || p.stride == 2u)));
  const uint ox0 = rows4 ? run_x + lane * NN_CONV_PIXELS : run_x + lane;
  const uint ox_step = rows4 ? 1u : NN_CONV_LANES;
  const uint oy = run / runs_x;
  const uint o0 = gl_WorkGroupID.y * NN_CONV_OUTPUTS;
  const uint outputs = min(NN_CONV_OUTPUTS, p.out_channels - o0);
  const int y0 = int(oy * p.stride) - int(p.pad), x0 = int(ox0 * p.stride) - int(p.pad);
  const uint taps_per_output = p.in_channels * p.kernel * p.kernel;
  // The packed weights' groups of four output channels. On every path a block past the last four reads the
  // last four's weights again and never writes them (the packing's zeros fill the last four).
  const uint fours = (p.out_channels + 3u) / 4u;
  // Constant bounds throughout, so that the compiler unrolls them and keeps the tile in registers.
  float sum[NN_CONV_OUTPUTS][NN_CONV_PIXELS];
  [[unroll]] for (uint j = 0u; j < NN_CONV_OUTPUTS; ++j) {
    const float bias = b[min(o0 + j, p.out_channels - 1u)];
    [[unroll]] for (uint q = 0u; q < NN_CONV_PIXELS; ++q) sum[j][q] = bias;
  }
  // All four pixels are inside or none: the output's width is a multiple of four.
  const bool inside = ox0 < p.out_width;
  const uint row_texels = p.in_width / 4u, centre = ox0 * p.stride / 4u;  // the texel of the first pixel
  if (rows4 && p.kernel == 1u) {
    for (uint c = 0u; c < p.in_channels; ++c) {
      const vec4 v = inside ? texelFetch(x4, int((c * p.in_height + oy) * row_texels + centre)) : vec4(0.0);
      [[unroll]] for (uint f = 0u; f < NN_CONV_OUTPUTS / 4u; ++f) {
        const vec4 w4 = texelFetch(w, int(min(o0 / 4u + f, fours - 1u) * taps_per_output + c));
        NN_CONV_ACCUMULATE(f, w4, v);
      }
    }
  } else if (rows4) {
    for (uint c = 0u; c < p.in_channels; ++c) {
      for (uint ky = 0u; ky < 3u; ++ky) {
        const int sy = y0 + int(ky);
        if (sy < 0 || sy >= int(p.in_height)) continue;
        const uint row = (c * p.in_height + uint(sy)) * row_texels;
        // The texels left of, at and right of the first pixel's (zero in the padding).
        const vec4 l4 = inside && centre > 0u ? texelFetch(x4, int(row + centre - 1u)) : vec4(0.0);
        const vec4 m4 = inside ? texelFetch(x4, int(row + centre)) : vec4(0.0);
        const vec4 r4 = inside && centre + 1u < row_texels ? texelFetch(x4, int(row + centre + 1u)) : vec4(0.0);
        // The input under each pixel at kernel columns 0, 1, 2 (stride 1: x - 1 .. x + 1; 2: 2x - 1 .. 2x + 1).
        vec4 v[3];
        if (p.stride == 1u) {
          v[0] = vec4(l4.w, m4.xyz);
          v[1] = m4;
          v[2] = vec4(m4.yzw, r4.x);
        } else {
          v[0] = vec4(l4.w, m4.y, m4.w, r4.y);
          v[1] = vec4(m4.x, m4.z, r4.x, r4.z);
          v[2] = vec4(m4.y, m4.w, r4.y, r4.w);
        }
        [[unroll]] for (uint kx = 0u; kx < 3u; ++kx) {
          const uint tap = (c * 3u + ky) * 3u + kx;
          [[unroll]] for (uint f = 0u; f < NN_CONV_OUTPUTS / 4u; ++f) {
            const vec4 w4 = texelFetch(w, int(min(o0 / 4u + f, fours - 1u) * taps_per_output + tap));
            NN_CONV_ACCUMULATE(f, w4, v[kx]);
          }
        }
      }
    }
  } else {
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
          [[unroll]] for (uint f = 0u; f < NN_CONV_OUTPUTS / 4u; ++f) {
            const vec4 w4 = texelFetch(w, int(min(o0 / 4u + f, fours - 1u) * taps_per_output + tap));
            NN_CONV_ACCUMULATE(f, w4, v);
          }
        }
      }
    }
  }
  const uint plane_out = p.out_height * p.out_width;
  for (uint j = 0u; j < outputs; ++j) {
    for (uint q = 0u; q < NN_CONV_PIXELS; ++q) {
      const uint ox = ox0 + q * ox_step;
      if (ox >= p.out_width) break;
      float s = sum[j][q];
      if (p.activation == NN_ACTIVATION_RELU) s = max(s, 0.0);
      if (p.activation == NN_ACTIVATION_SIGMOID) s = 1.0 / (1.0 + exp(-s));
      const uint e = (o0 + j) * plane_out + oy * p.out_width + ox;
      // A residual connection's add, here rather than in a pass of its own over both maps.
      if (p.has_residual != 0u) s += r[e];
      y[e] = s;
    }
  }
}
