#version 450
#extension GL_GOOGLE_include_directive : require
#extension GL_EXT_control_flow_attributes : require
// y = scale a b^T or y = a b (kernels/nn/attention_reference.cc's multiply_transposed, multiply): an
// invocation computes a register tile of NN_MATMUL_ROWS rows x NN_MATMUL_OUTPUTS columns of y, so that each
// value of a serves all the tile's columns and each value of b all its rows; the columns of NN_MATMUL_LANES
// neighbouring invocations interleave (column q of lane l: l + q NN_MATMUL_LANES), so that their loads of
// b's rows are contiguous in y = a b. Each output summed over k in order.
#include "limits.h"
#include "nn/nn_shared.h"
#include "elementwise.glsl"

// a and b are uniform texel buffers (R32_SFLOAT, nn_shared.h): a vector gather on CPU drivers.
layout(binding = NN_MATMUL_BINDING_A) uniform samplerBuffer a;
layout(binding = NN_MATMUL_BINDING_B) uniform samplerBuffer b;
layout(std430, binding = NN_MATMUL_BINDING_Y) writeonly buffer Y { float y[]; };
layout(push_constant) uniform Push { NnMatmulParams p; };

void main() {
  const uint e = elementwise_index();
  if (e >= p.count) return;
  const uint runs = (p.m + NN_MATMUL_RUN - 1u) / NN_MATMUL_RUN;
  const uint run = e / NN_MATMUL_LANES;
  const uint c0 = (run % runs) * NN_MATMUL_RUN + e % NN_MATMUL_LANES;
  const uint r0 = (run / runs) * NN_MATMUL_ROWS;
  float sum[NN_MATMUL_ROWS][NN_MATMUL_OUTPUTS];
  [[unroll]] for (uint i = 0u; i < NN_MATMUL_ROWS; ++i)
    [[unroll]] for (uint j = 0u; j < NN_MATMUL_OUTPUTS; ++j) sum[i][j] = 0.0;
  for (uint k = 0u; k < p.k; ++k) {
    // Rows and columns past the edges read the last one again and are never written.
    float va[NN_MATMUL_ROWS], vb[NN_MATMUL_OUTPUTS];
    [[unroll]] for (uint i = 0u; i < NN_MATMUL_ROWS; ++i) va[i] = texelFetch(a, int(p.a_offset + min(r0 + i, p.n - 1u) * p.k + k)).x;
    [[unroll]] for (uint j = 0u; j < NN_MATMUL_OUTPUTS; ++j) {
      const uint c = min(c0 + j * NN_MATMUL_LANES, p.m - 1u);
      vb[j] = texelFetch(b, int(p.b_offset + (p.transposed != 0u ? c * p.k + k : k * p.m + c))).x;
    }
    [[unroll]] for (uint i = 0u; i < NN_MATMUL_ROWS; ++i)
      [[unroll]] for (uint j = 0u; j < NN_MATMUL_OUTPUTS; ++j) sum[i][j] += va[i] * vb[j];
  }
  for (uint i = 0u; i < NN_MATMUL_ROWS; ++i) {
    const uint row = r0 + i;
    if (row >= p.n) break;
    for (uint j = 0u; j < NN_MATMUL_OUTPUTS; ++j) {
      const uint c = c0 + j * NN_MATMUL_LANES;
      if (c >= p.m) break;
      y[p.y_offset + row * p.m + c] = p.transposed != 0u ? p.scale * sum[i][j] : sum[i][j];
    }
  }
}
