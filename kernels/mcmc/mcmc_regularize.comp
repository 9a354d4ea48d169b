#version 450
#extension GL_GOOGLE_include_directive : require
// Per Gaussian, after the backward: the gradients of 3DGS-MCMC's regularizers
// opacity_reg * mean(opacity) + scale_reg * mean(scale), added to the rasterizer's gradients.
#include "limits.h"
#include "elementwise.glsl"
#include "mcmc/mcmc_shared.h"

layout(std430, binding = REG_BINDING_OPACITY_LOGITS) readonly buffer Logits { float opacity_logits[]; };
layout(std430, binding = REG_BINDING_LOG_SCALES) readonly buffer LogScales { float log_scales[]; };
layout(std430, binding = REG_BINDING_GRAD_OPACITY) buffer GradOpacity { float grad_opacity[]; };
layout(std430, binding = REG_BINDING_GRAD_LOG_SCALES) buffer GradLogScales { float grad_log_scales[]; };
layout(push_constant) uniform Push { McmcParams p; };

void main() {
  const uint i = elementwise_index();
  if (i >= p.count) return;
  const float o = 1.0 / (1.0 + exp(-opacity_logits[i]));
  grad_opacity[i] += p.opacity_reg * o * (1.0 - o);  // d sigmoid / d logit
  for (uint k = 0u; k < 3u; ++k)
    grad_log_scales[3 * i + k] += p.scale_reg * exp(min(log_scales[3 * i + k], 20.0));
}
