#version 450
#extension GL_GOOGLE_include_directive : require
#extension GL_EXT_control_flow_attributes : require
// y = [a | b] w + bias (+ r), as kernels/nn/attention_reference.cc's linear (concat_columns, add): an
// invocation computes NN_LINEAR_OUTPUTS neighbouring outputs of one row, each input value loaded once for
// all of them; each output summed over the inputs in order.
#include "limits.h"
#include "nn/nn_shared.h"
#include "elementwise.glsl"

// a, b and w are uniform texel buffers (R32_SFLOAT, nn_shared.h): a vector gather on CPU drivers.
layout(binding = NN_LINEAR_BINDING_A) uniform samplerBuffer a;
layout(binding = NN_LINEAR_BINDING_B) uniform samplerBuffer b;
layout(binding = NN_LINEAR_BINDING_W) uniform samplerBuffer w;
layout(std430, binding = NN_LINEAR_BINDING_BIAS) readonly buffer Bias { float bias[]; };
layout(std430, binding = NN_LINEAR_BINDING_R) readonly buffer R { float r[]; };
layout(std430, binding = NN_LINEAR_BINDING_Y) writeonly buffer Y { float y[]; };
layout(push_constant) uniform Push { NnLinearParams p; };

void main() {
  const uint e = elementwise_index();
  if (e >= p.count) return;
  const uint blocks = (p.outputs + NN_LINEAR_OUTPUTS - 1u) / NN_LINEAR_OUTPUTS;
  const uint row = e / blocks, o0 = (e % blocks) * NN_LINEAR_OUTPUTS;
  float sum[NN_LINEAR_OUTPUTS];
  [[unroll]] for (uint j = 0u; j < NN_LINEAR_OUTPUTS; ++j)
    sum[j] = p.has_bias != 0u ? bias[min(o0 + j, p.outputs - 1u)] : 0.0;
  for (uint i = 0u; i < p.a_cols + p.b_cols; ++i) {
    const float v = i < p.a_cols ? texelFetch(a, int(row * p.a_cols + i)).x
                                  : texelFetch(b, int(row * p.b_cols + i - p.a_cols)).x;
    // A block past the last output reads the last one's weights again and never writes them.
    [[unroll]] for (uint j = 0u; j < NN_LINEAR_OUTPUTS; ++j) sum[j] += v * texelFetch(w, int(i * p.outputs + min(o0 + j, p.outputs - 1u))).x;
  }
  for (uint j = 0u; j < NN_LINEAR_OUTPUTS; ++j) {
    const uint o = o0 + j;
    if (o >= p.outputs) break;
    y[row * p.outputs + o] = p.has_residual != 0u ? sum[j] + r[row * p.outputs + o] : sum[j];
  }
}
