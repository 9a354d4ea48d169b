#version 450
#extension GL_GOOGLE_include_directive : require
// Per Gaussian: dead or alive, and an alive Gaussian's sampling weight (its opacity, quantized).
#include "limits.h"
#include "elementwise.glsl"
#include "mcmc/mcmc_shared.h"

layout(std430, binding = WEIGHTS_BINDING_LOG_SCALES) readonly buffer LogScales { float log_scales[]; };
layout(std430, binding = WEIGHTS_BINDING_MEANS) readonly buffer Means { float means[]; };
layout(std430, binding = WEIGHTS_BINDING_QUATS) readonly buffer Quats { float quats[]; };
layout(std430, binding = WEIGHTS_BINDING_OPACITY_LOGITS) readonly buffer Logits { float opacity_logits[]; };
layout(std430, binding = WEIGHTS_BINDING_PLANE_DISTANCE) readonly buffer PlaneDistance {
  float plane_distance[];
};
layout(std430, binding = WEIGHTS_BINDING_WEIGHT) writeonly buffer Weight { uint weight[]; };
layout(std430, binding = WEIGHTS_BINDING_DEAD) writeonly buffer Dead { uint dead[]; };
layout(std430, binding = WEIGHTS_BINDING_REPORT) buffer Report { uint report[]; };
layout(push_constant) uniform Push { McmcParams p; };

void main() {
  const uint i = elementwise_index();
  if (i >= p.count) return;
  bool finite = true;
  for (uint k = 0u; k < 3u; ++k)
    finite = finite && finite_bits(means[3 * i + k]) && finite_bits(log_scales[3 * i + k]);
  for (uint k = 0u; k < 4u; ++k) finite = finite && finite_bits(quats[4 * i + k]);
  const float logit = opacity_logits[i];
  finite = finite && finite_bits(logit);
  int reason = -1;
  if (!finite)
    reason = MCMC_REPORT_DEAD_NONFINITE;
  else if (logit < p.min_opacity_logit)
    reason = MCMC_REPORT_DEAD_TRANSPARENT;
  else if ((p.flags & MCMC_FLAG_PLANE) != 0u && plane_distance[i] > p.max_plane_distance)
    reason = MCMC_REPORT_DEAD_PLANE;
  if (reason >= 0) atomicAdd(report[reason], 1u);
  dead[i] = reason >= 0 ? 1u : 0u;
  const float opacity = 1.0 / (1.0 + exp(-logit));
  weight[i] = reason >= 0 ? 0u : max(1u, uint(opacity * float(MCMC_WEIGHT_LEVELS) + 0.5));
}
