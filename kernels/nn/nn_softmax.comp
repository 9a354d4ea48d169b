#version 450
#extension GL_GOOGLE_include_directive : require
// The softmax or the log-sum-exp of each line of a, a line being a row or a column (nn_shared.h's
// NN_SOFTMAX_*), as kernels/nn/attention_reference.cc computes them: the line's largest value subtracted,
// the exps summed in order. A column's softmax is written as a row, so that the attention's second
// direction needs no transposed product. Generic path: one invocation per line. Quad path (rows of a that
// start on four-float boundaries): a row read four floats at a time, or four neighbouring columns per
// invocation, read as one four-float texel per row; each line's values in the same order.
#include "limits.h"
#include "nn/nn_shared.h"
#include "elementwise.glsl"

// a is a uniform texel buffer (R32_SFLOAT and R32G32B32A32_SFLOAT views, nn_shared.h): a vector gather, or
// one load per lane, on CPU drivers, where a storage buffer read at a per-lane index is a loop over the
// lanes. The exps are computed again rather than read back from `o` for the same reason.
layout(binding = NN_SOFTMAX_BINDING_A) uniform samplerBuffer a;
layout(binding = NN_SOFTMAX_BINDING_A4) uniform samplerBuffer a4;
layout(std430, binding = NN_SOFTMAX_BINDING_OUT) writeonly buffer Out { float o[]; };
layout(push_constant) uniform Push { NnSoftmaxParams p; };

const float kLowest = -3.4e38;

// One line, one float at a time (any layout).
void line_of_floats(uint line) {
  const uint first = line * p.line_step;
  float top = kLowest;
  for (uint t = 0u; t < p.line_length; ++t) top = max(top, texelFetch(a, int(first + t * p.step)).x);
  float sum = 0.0;
  for (uint t = 0u; t < p.line_length; ++t) sum += exp(texelFetch(a, int(first + t * p.step)).x - top);
  if (p.op == NN_SOFTMAX_LOG_SUM_EXP) {
    o[p.out_offset + line] = top + log(sum);
    return;
  }
  const uint first_out = p.out_offset + line * p.out_stride;
  for (uint t = 0u; t < p.line_length; ++t)
    o[first_out + t] = exp(texelFetch(a, int(first + t * p.step)).x - top) / sum;
}

// One row (line_step a multiple of four, step 1), four floats at a time, its last floats one at a time.
void row_of_quads(uint line) {
  const uint first = line * p.line_step, quads = p.line_length / 4u, first4 = first / 4u;
  float top = kLowest;
  for (uint t = 0u; t < quads; ++t) {
    const vec4 v = texelFetch(a4, int(first4 + t));
    top = max(max(max(top, v.x), v.y), max(v.z, v.w));
  }
  for (uint t = quads * 4u; t < p.line_length; ++t) top = max(top, texelFetch(a, int(first + t)).x);
  float sum = 0.0;
  for (uint t = 0u; t < quads; ++t) {
    const vec4 e = exp(texelFetch(a4, int(first4 + t)) - top);
    sum += e.x;
    sum += e.y;
    sum += e.z;
    sum += e.w;
  }
  for (uint t = quads * 4u; t < p.line_length; ++t) sum += exp(texelFetch(a, int(first + t)).x - top);
  if (p.op == NN_SOFTMAX_LOG_SUM_EXP) {
    o[p.out_offset + line] = top + log(sum);
    return;
  }
  const uint first_out = p.out_offset + line * p.out_stride;
  for (uint t = 0u; t < quads; ++t) {
    const vec4 s = exp(texelFetch(a4, int(first4 + t)) - top) / sum;
    o[first_out + 4u * t] = s.x;
    o[first_out + 4u * t + 1u] = s.y;
    o[first_out + 4u * t + 2u] = s.z;
    o[first_out + 4u * t + 3u] = s.w;
  }
  for (uint t = quads * 4u; t < p.line_length; ++t)
    o[first_out + t] = exp(texelFetch(a, int(first + t)).x - top) / sum;
}

// Columns 4q .. 4q + 3 (line_step 1, step a multiple of four), one four-float texel per row: each column's
// values in order, as four lines at once. Columns past the last (inside the padding of a's rows) are read
// and never written.
void columns_of_quads(uint q) {
  const uint c0 = 4u * q, step4 = p.step / 4u;
  vec4 top = vec4(kLowest);
  for (uint t = 0u; t < p.line_length; ++t) top = max(top, texelFetch(a4, int(t * step4 + q)));
  vec4 sum = vec4(0.0);
  for (uint t = 0u; t < p.line_length; ++t) sum += exp(texelFetch(a4, int(t * step4 + q)) - top);
  const uint columns = min(4u, p.lines - c0);
  if (p.op == NN_SOFTMAX_LOG_SUM_EXP) {
    const vec4 lse = top + log(sum);
    for (uint j = 0u; j < columns; ++j) o[p.out_offset + c0 + j] = lse[j];
    return;
  }
  for (uint t = 0u; t < p.line_length; ++t) {
    const vec4 s = exp(texelFetch(a4, int(t * step4 + q)) - top) / sum;
    for (uint j = 0u; j < columns; ++j) o[p.out_offset + (c0 + j) * p.out_stride + t] = s[j];
  }
}

void main() {
  const uint e = elementwise_index();
  if (e >= p.count) return;
  if (p.path == NN_SOFTMAX_ROW_QUADS)
    row_of_quads(e);
  else if (p.path == NN_SOFTMAX_COLUMN_QUADS)
    columns_of_quads(e);
  else
    line_of_floats(e);
}
