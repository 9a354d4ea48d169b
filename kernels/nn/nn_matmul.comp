#version 450
#extension GL_GOOGLE_include_directive : require
#extension GL_EXT_control_flow_attributes : require
// y = scale a b^T or y = a b (kernels/nn/attention_reference.cc's multiply_transposed, multiply): an
// invocation computes a register tile of NN_MATMUL_ROWS rows x 4 columns of y, so that each value of a
// serves all the tile's columns and each value of b all its rows. Each output summed over k in order.
// The quad path reads both operands as four-float texels, one load per lane where a one-float texel is a
// vector gather on CPU drivers (nn_shared.h); the generic path, for rows that do not start on four-float
// boundaries, reads one float at a time, the columns of NN_MATMUL_LANES neighbouring invocations
// interleaved (column q of lane l: l + q NN_MATMUL_LANES) so that their loads of b's rows are contiguous.
#include "limits.h"
#include "nn/nn_shared.h"
#include "elementwise.glsl"
#include "nn/nn_tiles.glsl"

#if NN_MATMUL_OUTPUTS != 4
#error "the quad path's tile is one four-float texel of b wide"
#endif

layout(binding = NN_MATMUL_BINDING_A) uniform samplerBuffer a;
layout(binding = NN_MATMUL_BINDING_B) uniform samplerBuffer b;
layout(binding = NN_MATMUL_BINDING_A4) uniform samplerBuffer a4;
layout(binding = NN_MATMUL_BINDING_B4) uniform samplerBuffer b4;
layout(std430, binding = NN_MATMUL_BINDING_Y) writeonly buffer Y { float y[]; };
layout(push_constant) uniform Push { NnMatmulParams p; };

// Rows and columns past the edges read the last one again and are never written.
uint a_row(uint r0, uint i) { return p.a_offset + min(r0 + i, p.n - 1u) * p.a_stride; }

void store(uint r0, uint c0, uint column_step, const float sum[NN_MATMUL_ROWS][NN_MATMUL_OUTPUTS]) {
  for (uint i = 0u; i < NN_MATMUL_ROWS; ++i) {
    const uint row = r0 + i;
    if (row >= p.n) break;
    for (uint j = 0u; j < NN_MATMUL_OUTPUTS; ++j) {
      const uint c = c0 + j * column_step;
      if (c >= p.m) break;
      y[p.y_offset + row * p.y_stride + c] = p.transposed != 0u ? p.scale * sum[i][j] : sum[i][j];
    }
  }
}

void main() {
  const uint e = elementwise_index();
  if (e >= p.count) return;
  float sum[NN_MATMUL_ROWS][NN_MATMUL_OUTPUTS];
  [[unroll]] for (uint i = 0u; i < NN_MATMUL_ROWS; ++i)
    [[unroll]] for (uint j = 0u; j < NN_MATMUL_OUTPUTS; ++j) sum[i][j] = 0.0;
  if (p.quads != 0u) {
    uint r0, c0;
    quad_tile(e, p.m, NN_MATMUL_ROWS, r0, c0);
    const uint quads = p.k / 4u;
    if (p.transposed != 0u) {
      // a b^T: rows of a and of b both run along k (k a multiple of four).
      uint b_rows[NN_MATMUL_OUTPUTS];
      [[unroll]] for (uint j = 0u; j < NN_MATMUL_OUTPUTS; ++j)
        b_rows[j] = (p.b_offset + min(c0 + j, p.m - 1u) * p.k) / 4u;
      for (uint t = 0u; t < quads; ++t) {
        vec4 vb[NN_MATMUL_OUTPUTS];
        [[unroll]] for (uint j = 0u; j < NN_MATMUL_OUTPUTS; ++j) vb[j] = texelFetch(b4, int(b_rows[j] + t));
        [[unroll]] for (uint i = 0u; i < NN_MATMUL_ROWS; ++i) {
          const vec4 va = texelFetch(a4, int(a_row(r0, i) / 4u + t));
          [[unroll]] for (uint j = 0u; j < NN_MATMUL_OUTPUTS; ++j)
            sum[i][j] = add_in_order(sum[i][j], va, vb[j]);
        }
      }
    } else {
      // a b: a's rows run along k, b's rows along the columns (m a multiple of four); k's last values past
      // its last whole quad are read one at a time.
      for (uint t = 0u; t < quads; ++t) {
        vec4 vb[4];  // b's rows 4t .. 4t + 3 at the tile's columns
        [[unroll]] for (uint q = 0u; q < 4u; ++q)
          vb[q] = texelFetch(b4, int((p.b_offset + (4u * t + q) * p.m + c0) / 4u));
        [[unroll]] for (uint i = 0u; i < NN_MATMUL_ROWS; ++i) {
          const vec4 va = texelFetch(a4, int(a_row(r0, i) / 4u + t));
          [[unroll]] for (uint j = 0u; j < NN_MATMUL_OUTPUTS; ++j)
            sum[i][j] = add_in_order(sum[i][j], va, vec4(vb[0][j], vb[1][j], vb[2][j], vb[3][j]));
        }
      }
      for (uint k = quads * 4u; k < p.k; ++k) {
        const vec4 vb = texelFetch(b4, int((p.b_offset + k * p.m + c0) / 4u));
        [[unroll]] for (uint i = 0u; i < NN_MATMUL_ROWS; ++i) {
          const float va = texelFetch(a, int(a_row(r0, i) + k)).x;
          [[unroll]] for (uint j = 0u; j < NN_MATMUL_OUTPUTS; ++j) sum[i][j] += va * vb[j];
        }
      }
    }
    store(r0, c0, 1u, sum);
    return;
  }
  uint r0, c0;
  interleaved_tile(e, p.m, NN_MATMUL_ROWS, NN_MATMUL_LANES, NN_MATMUL_OUTPUTS, r0, c0);
  for (uint k = 0u; k < p.k; ++k) {
    float va[NN_MATMUL_ROWS], vb[NN_MATMUL_OUTPUTS];
    [[unroll]] for (uint i = 0u; i < NN_MATMUL_ROWS; ++i) va[i] = texelFetch(a, int(a_row(r0, i) + k)).x;
    [[unroll]] for (uint j = 0u; j < NN_MATMUL_OUTPUTS; ++j) {
      const uint c = min(c0 + j * NN_MATMUL_LANES, p.m - 1u);
      vb[j] = texelFetch(b, int(p.b_offset + (p.transposed != 0u ? c * p.k + k : k * p.m + c))).x;
    }
    [[unroll]] for (uint i = 0u; i < NN_MATMUL_ROWS; ++i)
      [[unroll]] for (uint j = 0u; j < NN_MATMUL_OUTPUTS; ++j) sum[i][j] += va[i] * vb[j];
  }
  store(r0, c0, NN_MATMUL_LANES, sum);
}
