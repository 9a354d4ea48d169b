#version 450
#extension GL_GOOGLE_include_directive : require
// Per Gaussian drawn c > 0 times: it and its c copies share its opacity profile (3DGS-MCMC eq. 9).
#include "limits.h"
#include "elementwise.glsl"
#include "mcmc/mcmc_shared.h"
#include "splat/splat_shared.h"
#include "splat/splat_math.h"
#include "densify/densify_shared.h"
#include "densify/densify_math.h"
#include "mcmc/mcmc_math.h"

layout(std430, binding = UPDATE_BINDING_COPIES) readonly buffer Copies { uint copies[]; };
layout(std430, binding = UPDATE_BINDING_OPACITY_LOGITS) buffer Logits { float opacity_logits[]; };
layout(std430, binding = UPDATE_BINDING_LOG_SCALES) buffer LogScales { float log_scales[]; };
layout(push_constant) uniform Push { McmcParams p; };

void main() {
  const uint i = elementwise_index();
  if (i >= p.count || copies[i] == 0u) return;
  const uint n = min(copies[i] + 1u, MCMC_MAX_COPIES);
  const float o = 1.0 / (1.0 + exp(-opacity_logits[i]));
  const float o_new = relocated_opacity(o, n);
  const float delta = relocation_log_scale_delta(o, o_new, n);
  const float clamped = clamp(o_new, p.min_opacity, 1.0 - 1.0 / 8388608.0);
  opacity_logits[i] = log(clamped / (1.0 - clamped));
  for (uint k = 0u; k < 3u; ++k) log_scales[3 * i + k] += delta;
}
