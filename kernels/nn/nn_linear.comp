#version 450
#extension GL_GOOGLE_include_directive : require
#extension GL_EXT_control_flow_attributes : require
// y = [a | b] w + bias (+ r), as kernels/nn/attention_reference.cc's linear (concat_columns, add): an
// invocation computes a register tile of NN_LINEAR_ROWS rows x NN_LINEAR_OUTPUTS outputs, so that each
// input value serves all the tile's outputs and each weight all its rows. Each output is the bias, then the
// inputs in order, then the residual. The quad path (widths that are multiples of four) reads the rows and
// the weights as four-float texels, one load per lane where a one-float texel is a vector gather on CPU
// drivers (nn_shared.h), its outputs neighbours; the generic path reads one float at a time, the outputs of
// NN_LINEAR_LANES neighbouring invocations interleaved so that their loads of a row of weights are
// contiguous.
#include "limits.h"
#include "nn/nn_shared.h"
#include "elementwise.glsl"
#include "nn/nn_tiles.glsl"

#if NN_LINEAR_OUTPUTS != 4
#error "the quad path's tile is one four-float texel of weights wide"
#endif

layout(binding = NN_LINEAR_BINDING_A) uniform samplerBuffer a;
layout(binding = NN_LINEAR_BINDING_B) uniform samplerBuffer b;
layout(binding = NN_LINEAR_BINDING_W) uniform samplerBuffer w;
layout(binding = NN_LINEAR_BINDING_A4) uniform samplerBuffer a4;
layout(binding = NN_LINEAR_BINDING_B4) uniform samplerBuffer b4;
layout(binding = NN_LINEAR_BINDING_W4) uniform samplerBuffer w4;
layout(std430, binding = NN_LINEAR_BINDING_BIAS) readonly buffer Bias { float bias[]; };
layout(std430, binding = NN_LINEAR_BINDING_R) readonly buffer R { float residual[]; };
layout(std430, binding = NN_LINEAR_BINDING_Y) writeonly buffer Y { float y[]; };
layout(push_constant) uniform Push { NnLinearParams p; };

float sum[NN_LINEAR_ROWS][NN_LINEAR_OUTPUTS];

// Adds input i of the tile's rows (v) times the weights of input i (the generic path).
void accumulate(const float v[NN_LINEAR_ROWS], uint i, uint o0) {
  // Outputs past the last read the last one's weights again and are never written.
  float vw[NN_LINEAR_OUTPUTS];
  [[unroll]] for (uint j = 0u; j < NN_LINEAR_OUTPUTS; ++j)
    vw[j] = texelFetch(w, int(i * p.outputs + min(o0 + j * NN_LINEAR_LANES, p.outputs - 1u))).x;
  [[unroll]] for (uint r = 0u; r < NN_LINEAR_ROWS; ++r)
    [[unroll]] for (uint j = 0u; j < NN_LINEAR_OUTPUTS; ++j) sum[r][j] += v[r] * vw[j];
}

// The quad path: loads the weights of inputs 4t .. 4t + 3 at outputs o0 .. o0 + 3.
void weight_quad(uint t, uint o0, out vec4 vw[4]) {
  [[unroll]] for (uint q = 0u; q < 4u; ++q) vw[q] = texelFetch(w4, int(((4u * t + q) * p.outputs + o0) / 4u));
}

// The quad path: adds four inputs of the tile's row r (v) times their weights (vw).
void accumulate_quad(uint r, vec4 v, const vec4 vw[4]) {
  [[unroll]] for (uint j = 0u; j < NN_LINEAR_OUTPUTS; ++j)
    sum[r][j] = add_in_order(sum[r][j], v, vec4(vw[0][j], vw[1][j], vw[2][j], vw[3][j]));
}

void main() {
  const uint e = elementwise_index();
  if (e >= p.count) return;
  uint r0, o0;
  const uint step = p.quads != 0u ? 1u : NN_LINEAR_LANES;  // from one of the tile's outputs to the next
  if (p.quads != 0u)
    quad_tile(e, p.outputs, NN_LINEAR_ROWS, r0, o0);
  else
    interleaved_tile(e, p.outputs, NN_LINEAR_ROWS, NN_LINEAR_LANES, NN_LINEAR_OUTPUTS, r0, o0);
  [[unroll]] for (uint j = 0u; j < NN_LINEAR_OUTPUTS; ++j) {
    const float b0 = p.has_bias != 0u ? bias[min(o0 + j * step, p.outputs - 1u)] : 0.0;
    [[unroll]] for (uint r = 0u; r < NN_LINEAR_ROWS; ++r) sum[r][j] = b0;
  }
  // Rows past the last read the last one again and are never written.
  uint row[NN_LINEAR_ROWS];
  [[unroll]] for (uint r = 0u; r < NN_LINEAR_ROWS; ++r) row[r] = min(r0 + r, p.rows - 1u);
  if (p.quads != 0u) {
    const uint a_quads = p.a_cols / 4u, b_quads = p.b_cols / 4u;
    for (uint t = 0u; t < a_quads; ++t) {
      vec4 vw[4];
      weight_quad(t, o0, vw);
      [[unroll]] for (uint r = 0u; r < NN_LINEAR_ROWS; ++r)
        accumulate_quad(r, texelFetch(a4, int(row[r] * a_quads + t)), vw);
    }
    for (uint t = 0u; t < b_quads; ++t) {
      vec4 vw[4];
      weight_quad(a_quads + t, o0, vw);
      [[unroll]] for (uint r = 0u; r < NN_LINEAR_ROWS; ++r)
        accumulate_quad(r, texelFetch(b4, int(row[r] * b_quads + t)), vw);
    }
  } else {
    for (uint i = 0u; i < p.a_cols; ++i) {
      float v[NN_LINEAR_ROWS];
      [[unroll]] for (uint r = 0u; r < NN_LINEAR_ROWS; ++r)
        v[r] = texelFetch(a, int(row[r] * p.a_cols + i)).x;
      accumulate(v, i, o0);
    }
    for (uint i = 0u; i < p.b_cols; ++i) {
      float v[NN_LINEAR_ROWS];
      [[unroll]] for (uint r = 0u; r < NN_LINEAR_ROWS; ++r)
        v[r] = texelFetch(b, int(row[r] * p.b_cols + i)).x;
      accumulate(v, p.a_cols + i, o0);
    }
  }
  for (uint r = 0u; r < NN_LINEAR_ROWS; ++r) {
    if (r0 + r >= p.rows) break;
    for (uint j = 0u; j < NN_LINEAR_OUTPUTS; ++j) {
      const uint o = o0 + j * step;
      if (o >= p.outputs) break;
      const uint at = (r0 + r) * p.outputs + o;
      y[at] = p.has_residual != 0u ? sum[r][j] + residual[at] : sum[r][j];
    }
  }
}
