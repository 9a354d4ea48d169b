#version 450
#extension GL_GOOGLE_include_directive : require
#extension GL_EXT_control_flow_attributes : require
// y = scale a b^T or y = a b (kernels/nn/attention_reference.cc's multiply_transposed, multiply): an
// invocation computes NN_MATMUL_OUTPUTS neighbouring columns of one row of y, each value of a's row loaded
// once for all of them; each output summed over k in order.
#include "limits.h"
#include "nn/nn_shared.h"
#include "elementwise.glsl"

layout(std430, binding = NN_MATMUL_BINDING_A) readonly buffer A { float a[]; };
layout(std430, binding = NN_MATMUL_BINDING_B) readonly buffer B { float b[]; };
layout(std430, binding = NN_MATMUL_BINDING_Y) writeonly buffer Y { float y[]; };
layout(push_constant) uniform Push { NnMatmulParams p; };

void main() {
  const uint e = elementwise_index();
  if (e >= p.count) return;
  const uint blocks = (p.m + NN_MATMUL_OUTPUTS - 1u) / NN_MATMUL_OUTPUTS;
  const uint row = e / blocks, c0 = (e % blocks) * NN_MATMUL_OUTPUTS;
  float sum[NN_MATMUL_OUTPUTS];
  [[unroll]] for (uint j = 0u; j < NN_MATMUL_OUTPUTS; ++j) sum[j] = 0.0;
  for (uint k = 0u; k < p.k; ++k) {
    const float v = a[p.a_offset + row * p.k + k];
    // A block past the last column reads the last one again and never writes it.
    [[unroll]] for (uint j = 0u; j < NN_MATMUL_OUTPUTS; ++j) {
      const uint c = min(c0 + j, p.m - 1u);
      sum[j] += v * b[p.b_offset + (p.transposed != 0u ? c * p.k + k : k * p.m + c)];
    }
  }
  for (uint j = 0u; j < NN_MATMUL_OUTPUTS; ++j) {
    const uint c = c0 + j;
    if (c >= p.m) break;
    y[p.y_offset + row * p.m + c] = p.transposed != 0u ? p.scale * sum[j] : sum[j];
  }
}
