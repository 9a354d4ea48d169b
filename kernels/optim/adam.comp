#version 450
#extension GL_GOOGLE_include_directive : require
// Adam, bias-corrected as torch.optim.Adam (no weight decay, no amsgrad), one element per invocation.
#include "limits.h"
#include "optim/optim_shared.h"
#include "elementwise.glsl"
#include "optim/adam_step.glsl"

layout(std430, binding = ADAM_BINDING_PARAMS) buffer Params { float params[]; };
layout(std430, binding = ADAM_BINDING_GRADS) readonly buffer Grads { float grads[]; };
layout(std430, binding = ADAM_BINDING_EXP_AVG) buffer ExpAvg { float exp_avg[]; };
layout(std430, binding = ADAM_BINDING_EXP_AVG_SQ) buffer ExpAvgSq { float exp_avg_sq[]; };
layout(std430, binding = ADAM_BINDING_COUNTERS) buffer Counters { uint counters[]; };
layout(push_constant) uniform Push { AdamParams p; };

void main() {
  const uint j = elementwise_index();
  if (j >= p.count) return;
  const float lr = (j % p.period) < p.lead ? p.lr : p.lr_rest;
  float x = params[j], m = exp_avg[j], v = exp_avg_sq[j];
  if (!adam_step_value(p, lr, grads[j], x, m, v)) {
    atomicAdd(counters[p.counter_slot], 1u);
    return;
  }
  exp_avg[j] = m;
  exp_avg_sq[j] = v;
  params[j] = x;
}
