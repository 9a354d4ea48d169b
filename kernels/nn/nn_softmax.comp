#version 450
#extension GL_GOOGLE_include_directive : require
// The softmax or the log-sum-exp of each line of a, a line being a row or a column (nn_shared.h's
// NN_SOFTMAX_*), as kernels/nn/attention_reference.cc computes them: the line's largest value subtracted,
// the exps summed in order. One invocation per line. A column's softmax is written as a row, so that the
// attention's second direction needs no transposed product.
#include "limits.h"
#include "nn/nn_shared.h"
#include "elementwise.glsl"

// a is a uniform texel buffer (R32_SFLOAT, nn_shared.h): a vector gather on CPU drivers, where a storage
// buffer read at a per-lane index is a loop over the lanes. The exps are computed again rather than read
// back from `o` for the same reason.
layout(binding = NN_SOFTMAX_BINDING_A) uniform samplerBuffer a;
layout(std430, binding = NN_SOFTMAX_BINDING_OUT) writeonly buffer Out { float o[]; };
layout(push_constant) uniform Push { NnSoftmaxParams p; };

void main() {
  const uint line = elementwise_index();
  if (line >= p.lines) return;
  const uint first = line * p.line_step;
  float top = -3.4e38;
  for (uint t = 0u; t < p.line_length; ++t) top = max(top, texelFetch(a, int(first + t * p.step)).x);
  float sum = 0.0;
  for (uint t = 0u; t < p.line_length; ++t) sum += exp(texelFetch(a, int(first + t * p.step)).x - top);
  if (p.op == NN_SOFTMAX_LOG_SUM_EXP) {
    o[p.out_offset + line] = top + log(sum);
    return;
  }
  const uint first_out = p.out_offset + line * p.out_stride;
  for (uint t = 0u; t < p.line_length; ++t) o[first_out + t] = exp(texelFetch(a, int(first + t * p.step)).x - top) / sum;
}
