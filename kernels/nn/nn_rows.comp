#version 450
#extension GL_GOOGLE_include_directive : require
// The attention matcher's row operations (nn_shared.h's NN_ROWS_*), each as kernels/nn/attention_reference.cc
// and lighterglue_reference.cc compute it: layer norm then GELU, the log assignment, and the split of q, k, v
// with the rotary encoding of q and k. The softmax and the log-sum-exps are nn_softmax.comp's.
#include "limits.h"
#include "nn/nn_shared.h"
#include "elementwise.glsl"

layout(std430, binding = NN_ROWS_BINDING_A) buffer A { float a[]; };
layout(std430, binding = NN_ROWS_BINDING_B) readonly buffer B { float b[]; };
layout(std430, binding = NN_ROWS_BINDING_C) readonly buffer C { float c[]; };
layout(std430, binding = NN_ROWS_BINDING_OUT) writeonly buffer Out { float o[]; };
layout(push_constant) uniform Push { NnRowsParams p; };

// erf by Abramowitz and Stegun 7.1.26 (absolute error below 1.5e-7, float's own precision near 1): GLSL has
// no erf.
float erf_as(float x) {
  const float t = 1.0 / (1.0 + 0.3275911 * abs(x));
  const float poly = t * (0.254829592 + t * (-0.284496736 + t * (1.421413741 + t * (-1.453152027 + t * 1.061405429))));
  return sign(x) * (1.0 - poly * exp(-x * x));
}

float log_sigmoid(float z) { return z >= 0.0 ? -log(1.0 + exp(-z)) : z - log(1.0 + exp(z)); }

void main() {
  const uint e = elementwise_index();
  if (e >= p.count) return;
  if (p.op == NN_ROWS_LAYER_NORM_GELU) {
    const uint first = e * p.cols;
    float mean = 0.0, var = 0.0;
    for (uint i = 0u; i < p.cols; ++i) mean += a[first + i];
    mean /= float(p.cols);
    for (uint i = 0u; i < p.cols; ++i) var += (a[first + i] - mean) * (a[first + i] - mean);
    const float inv = inversesqrt(var / float(p.cols) + p.epsilon);
    for (uint i = 0u; i < p.cols; ++i) {
      const float x = (a[first + i] - mean) * inv * b[i] + c[i];
      a[first + i] = 0.5 * x * (1.0 + erf_as(x * 0.70710678118654752));
    }
  } else if (p.op == NN_ROWS_ASSIGNMENT) {
    const uint i = e / p.cols, j = e % p.cols;
    o[e] = (a[e] - b[i]) + (a[e] - b[p.rows + j]) + log_sigmoid(c[i]) + log_sigmoid(c[p.rows + j]);
  } else if (p.op == NN_ROWS_SPLIT_ROTARY) {
    const uint half_dim = p.cols / 2u;
    const uint row = e / half_dim, k = e % half_dim;
    const float f = b[2u * row] * c[k] + b[2u * row + 1u] * c[half_dim + k];
    const float cs = cos(f), sn = sin(f);
    const uint in0 = row * 3u * p.cols + 3u * (2u * k), in1 = in0 + 3u;  // channels 2k and 2k + 1
    const uint plane = p.rows * p.cols, out0 = row * p.cols + 2u * k;
    const float qa = a[in0], qb = a[in1], ka = a[in0 + 1u], kb = a[in1 + 1u];
    o[out0] = qa * cs - qb * sn;
    o[out0 + 1u] = qb * cs + qa * sn;
    o[plane + out0] = ka * cs - kb * sn;
    o[plane + out0 + 1u] = kb * cs + ka * sn;
    o[2u * plane + out0] = a[in0 + 2u];
    o[2u * plane + out0 + 1u] = a[in1 + 2u];
  }
}
