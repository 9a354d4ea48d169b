#version 450
#extension GL_GOOGLE_include_directive : require
// The attention matcher's row operations (nn_shared.h's NN_ROWS_*), each as kernels/nn/attention_reference.cc
// and lighterglue_reference.cc compute it: layer norm then GELU, the matchability logits' log-sigmoids, the
// log assignment, and the split of q, k, v with the rotary encoding of q and k. The softmax and the
// log-sum-exps are nn_softmax.comp's.
#include "limits.h"
#include "nn/nn_shared.h"
#include "elementwise.glsl"

// a, b and c are uniform texel buffers (R32_SFLOAT, a and b again as R32G32B32A32_SFLOAT): a vector gather, or
// one load per lane, on CPU drivers, where a storage buffer read at a per-lane index is a loop over the
// lanes. The layer norm writes its rows through `o`, bound to a's buffer.
layout(binding = NN_ROWS_BINDING_A) uniform samplerBuffer a;
layout(binding = NN_ROWS_BINDING_A4) uniform samplerBuffer a4;
layout(binding = NN_ROWS_BINDING_B4) uniform samplerBuffer b4;
layout(binding = NN_ROWS_BINDING_B) uniform samplerBuffer b;
layout(binding = NN_ROWS_BINDING_C) uniform samplerBuffer c;
layout(std430, binding = NN_ROWS_BINDING_OUT) writeonly buffer Out { float o[]; };
layout(push_constant) uniform Push { NnRowsParams p; };

// erf by Abramowitz and Stegun 7.1.26 (absolute error below 1.5e-7, float's own precision near 1): GLSL has
// no erf.
vec4 erf_as(vec4 x) {
  const vec4 t = 1.0 / (1.0 + 0.3275911 * abs(x));
  const vec4 poly = t * (0.254829592 + t * (-0.284496736 + t * (1.421413741 + t * (-1.453152027 + t * 1.061405429))));
  return sign(x) * (1.0 - poly * exp(-x * x));
}

float log_sigmoid(float z) { return z >= 0.0 ? -log(1.0 + exp(-z)) : z - log(1.0 + exp(z)); }

float at(samplerBuffer t, uint i) { return texelFetch(t, int(i)).x; }

vec4 gelu(vec4 x) { return 0.5 * x * (1.0 + erf_as(x * 0.70710678118654752)); }

// Row r: each sum over its values in order, read four floats at a time where the rows start on four-float
// boundaries (p.quads), else one at a time.
void layer_norm_gelu(uint r) {
  const uint first = r * p.cols;
  const float width = float(p.cols);
  float mean = 0.0, var = 0.0;
  if (p.quads != 0u) {
    const uint first4 = first / 4u, quads = p.cols / 4u;
    for (uint q = 0u; q < quads; ++q) {
      const vec4 v = texelFetch(a4, int(first4 + q));
      mean += v.x;
      mean += v.y;
      mean += v.z;
      mean += v.w;
    }
    mean /= width;
    for (uint q = 0u; q < quads; ++q) {
      const vec4 d = texelFetch(a4, int(first4 + q)) - mean;
      var += d.x * d.x;
      var += d.y * d.y;
      var += d.z * d.z;
      var += d.w * d.w;
    }
    const float inv = inversesqrt(var / width + p.epsilon);
    for (uint q = 0u; q < quads; ++q) {
      const uint i = 4u * q;
      const vec4 scale = vec4(at(b, i), at(b, i + 1u), at(b, i + 2u), at(b, i + 3u));
      const vec4 shift = vec4(at(c, i), at(c, i + 1u), at(c, i + 2u), at(c, i + 3u));
      const vec4 y = gelu((texelFetch(a4, int(first4 + q)) - mean) * inv * scale + shift);
      o[first + i] = y.x;
      o[first + i + 1u] = y.y;
      o[first + i + 2u] = y.z;
      o[first + i + 3u] = y.w;
    }
    return;
  }
  for (uint i = 0u; i < p.cols; ++i) mean += at(a, first + i);
  mean /= width;
  for (uint i = 0u; i < p.cols; ++i) var += (at(a, first + i) - mean) * (at(a, first + i) - mean);
  const float inv = inversesqrt(var / width + p.epsilon);
  for (uint i = 0u; i < p.cols; ++i)
    o[first + i] = gelu(vec4((at(a, first + i) - mean) * inv * at(b, i) + at(c, i))).x;
}

// b: the rows' log-sum-exps, then the columns' from NN_PADDED_ROW(rows); their log-sigmoids after them,
// from NN_PADDED_ROW(rows) + NN_PADDED_ROW(cols) (c, the same buffer). p.quads: four neighbouring entries of a
// row per invocation, each computed as the one-entry path computes it.
void assignment(uint e) {
  const uint columns = NN_PADDED_ROW(p.rows), sigmoids = columns + NN_PADDED_ROW(p.cols);
  if (p.quads != 0u) {
    const uint quads = p.cols / 4u, i = e / quads, q = e % quads;
    const vec4 s = texelFetch(a4, int(e));  // row i starts on a four-float boundary: e = i quads + q
    const vec4 y = (s - at(b, i)) + (s - texelFetch(b4, int(columns / 4u + q))) + at(b, sigmoids + i) +
                   texelFetch(b4, int((sigmoids + columns) / 4u + q));
    const uint first = 4u * e;
    o[first] = y.x;
    o[first + 1u] = y.y;
    o[first + 2u] = y.z;
    o[first + 3u] = y.w;
    return;
  }
  const uint i = e / p.cols, j = e % p.cols;
  const float s = at(a, e);
  o[e] = (s - at(b, i)) + (s - at(b, columns + j)) + at(c, sigmoids + i) + at(c, sigmoids + columns + j);
}

void main() {
  const uint e = elementwise_index();
  if (e >= p.count) return;
  if (p.op == NN_ROWS_LAYER_NORM_GELU) {
    layer_norm_gelu(e);
  } else if (p.op == NN_ROWS_LOG_SIGMOID) {
    o[p.out_offset + (e < p.rows ? e : e - p.rows + NN_PADDED_ROW(p.rows))] = log_sigmoid(at(a, e));
  } else if (p.op == NN_ROWS_ASSIGNMENT) {
    assignment(e);
  } else if (p.op == NN_ROWS_SPLIT_ROTARY) {
    const uint half_dim = p.cols / 2u;
    const uint row = e / half_dim, k = e % half_dim;
    const float f = at(b, 2u * row) * at(c, k) + at(b, 2u * row + 1u) * at(c, half_dim + k);
    const float cs = cos(f), sn = sin(f);
    const uint in0 = row * 3u * p.cols + 3u * (2u * k), in1 = in0 + 3u;  // channels 2k and 2k + 1
    const uint plane = p.rows * p.cols, out0 = row * p.cols + 2u * k;
    const float qa = at(a, in0), qb = at(a, in1), ka = at(a, in0 + 1u), kb = at(a, in1 + 1u);
    o[out0] = qa * cs - qb * sn;
    o[out0 + 1u] = qb * cs + qa * sn;
    o[plane + out0] = ka * cs - kb * sn;
    o[plane + out0 + 1u] = kb * cs + ka * sn;
    o[2u * plane + out0] = at(a, in0 + 2u);
    o[2u * plane + out0 + 1u] = at(a, in1 + 2u);
  }
}
