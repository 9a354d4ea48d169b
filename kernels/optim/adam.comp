#version 450
#extension GL_GOOGLE_include_directive : require
// Adam, bias-corrected as torch.optim.Adam (no weight decay, no amsgrad), one element per invocation.
#include "limits.h"
#include "optim/optim_shared.h"
#include "elementwise.glsl"

layout(std430, binding = ADAM_BINDING_PARAMS) buffer Params { float params[]; };
layout(std430, binding = ADAM_BINDING_GRADS) readonly buffer Grads { float grads[]; };
layout(std430, binding = ADAM_BINDING_EXP_AVG) buffer ExpAvg { float exp_avg[]; };
layout(std430, binding = ADAM_BINDING_EXP_AVG_SQ) buffer ExpAvgSq { float exp_avg_sq[]; };
layout(std430, binding = ADAM_BINDING_COUNTERS) buffer Counters { uint counters[]; };
layout(push_constant) uniform Push { AdamParams p; };

void main() {
  const uint j = elementwise_index();
  if (j >= p.count) return;
  const float g = grads[j];
  const float lr = (j % p.period) < p.lead ? p.lr : p.lr_rest;
  const float m = p.beta1 * exp_avg[j] + (1.0 - p.beta1) * g;
  const float v = p.beta2 * exp_avg_sq[j] + (1.0 - p.beta2) * (g * g);
  const float denom = sqrt(v) / p.sqrt_bias_correction2 + p.eps;
  const float x = params[j] - (lr / p.bias_correction1) * (m / denom);
  if (!finite_bits(g) || !finite_bits(m) || !finite_bits(v) || !finite_bits(x)) {
    atomicAdd(counters[p.counter_slot], 1u);
    return;
  }
  exp_avg[j] = m;
  exp_avg_sq[j] = v;
  params[j] = x;
}
