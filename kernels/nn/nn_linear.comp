#version 450
#extension GL_GOOGLE_include_directive : require
#extension GL_EXT_control_flow_attributes : require
// y = [a | b] w + bias (+ r), as kernels/nn/attention_reference.cc's linear (concat_columns, add): an
// invocation computes a register tile of NN_LINEAR_ROWS rows x NN_LINEAR_OUTPUTS outputs, so that each
// input value serves all the tile's outputs and each weight all its rows; the outputs of NN_LINEAR_LANES
// neighbouring invocations interleave (output q of lane l: l + q NN_LINEAR_LANES), so that their loads of a
// row of weights are contiguous. Each output is the bias, then the inputs in order, then the residual.
#include "limits.h"
#include "nn/nn_shared.h"
#include "elementwise.glsl"

// a, b and w are uniform texel buffers (R32_SFLOAT, nn_shared.h): a vector gather on CPU drivers.
layout(binding = NN_LINEAR_BINDING_A) uniform samplerBuffer a;
layout(binding = NN_LINEAR_BINDING_B) uniform samplerBuffer b;
layout(binding = NN_LINEAR_BINDING_W) uniform samplerBuffer w;
layout(std430, binding = NN_LINEAR_BINDING_BIAS) readonly buffer Bias { float bias[]; };
layout(std430, binding = NN_LINEAR_BINDING_R) readonly buffer R { float residual[]; };
layout(std430, binding = NN_LINEAR_BINDING_Y) writeonly buffer Y { float y[]; };
layout(push_constant) uniform Push { NnLinearParams p; };

float sum[NN_LINEAR_ROWS][NN_LINEAR_OUTPUTS];

// Adds input i of the tile's rows (v) times the weights of input i.
void accumulate(const float v[NN_LINEAR_ROWS], uint i, uint o0) {
  // Outputs past the last read the last one's weights again and are never written.
  float vw[NN_LINEAR_OUTPUTS];
  [[unroll]] for (uint j = 0u; j < NN_LINEAR_OUTPUTS; ++j)
    vw[j] = texelFetch(w, int(i * p.outputs + min(o0 + j * NN_LINEAR_LANES, p.outputs - 1u))).x;
  [[unroll]] for (uint r = 0u; r < NN_LINEAR_ROWS; ++r)
    [[unroll]] for (uint j = 0u; j < NN_LINEAR_OUTPUTS; ++j) sum[r][j] += v[r] * vw[j];
}

void main() {
  const uint e = elementwise_index();
  if (e >= p.count) return;
  const uint runs = (p.outputs + NN_LINEAR_RUN - 1u) / NN_LINEAR_RUN;
  const uint run = e / NN_LINEAR_LANES;
  const uint o0 = (run % runs) * NN_LINEAR_RUN + e % NN_LINEAR_LANES;
  const uint r0 = (run / runs) * NN_LINEAR_ROWS;
  [[unroll]] for (uint j = 0u; j < NN_LINEAR_OUTPUTS; ++j) {
    const float b0 = p.has_bias != 0u ? bias[min(o0 + j * NN_LINEAR_LANES, p.outputs - 1u)] : 0.0;
    [[unroll]] for (uint r = 0u; r < NN_LINEAR_ROWS; ++r) sum[r][j] = b0;
  }
  // Rows past the last read the last one again and are never written.
  uint row[NN_LINEAR_ROWS];
  [[unroll]] for (uint r = 0u; r < NN_LINEAR_ROWS; ++r) row[r] = min(r0 + r, p.rows - 1u);
  for (uint i = 0u; i < p.a_cols; ++i) {
    float v[NN_LINEAR_ROWS];
    [[unroll]] for (uint r = 0u; r < NN_LINEAR_ROWS; ++r) v[r] = texelFetch(a, int(row[r] * p.a_cols + i)).x;
    accumulate(v, i, o0);
  }
  for (uint i = 0u; i < p.b_cols; ++i) {
    float v[NN_LINEAR_ROWS];
    [[unroll]] for (uint r = 0u; r < NN_LINEAR_ROWS; ++r) v[r] = texelFetch(b, int(row[r] * p.b_cols + i)).x;
    accumulate(v, p.a_cols + i, o0);
  }
  for (uint r = 0u; r < NN_LINEAR_ROWS; ++r) {
    if (r0 + r >= p.rows) break;
    for (uint j = 0u; j < NN_LINEAR_OUTPUTS; ++j) {
      const uint o = o0 + j * NN_LINEAR_LANES;
      if (o >= p.outputs) break;
      const uint at = (r0 + r) * p.outputs + o;
      y[at] = p.has_residual != 0u ? sum[r][j] + residual[at] : sum[r][j];
    }
  }
}
