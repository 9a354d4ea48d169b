// Shared by densify_candidates.comp and densify_decide.comp: the bindings and the per-Gaussian input.
#include "limits.h"
#include "elementwise.glsl"
#include "densify/densify_shared.h"
#include "densify/densify_math.h"

layout(std430, binding = DECIDE_BINDING_MEANS) readonly buffer Means { float means[]; };
layout(std430, binding = DECIDE_BINDING_LOG_SCALES) readonly buffer LogScales { float log_scales[]; };
layout(std430, binding = DECIDE_BINDING_QUATS) readonly buffer Quats { float quats[]; };
layout(std430, binding = DECIDE_BINDING_OPACITY_LOGITS) readonly buffer Logits { float opacity_logits[]; };
layout(std430, binding = DECIDE_BINDING_SH) readonly buffer Sh { float sh[]; };
layout(std430, binding = DECIDE_BINDING_GRAD_ACCUM) readonly buffer GradAccum { float grad_accum[]; };
layout(std430, binding = DECIDE_BINDING_DENOM) readonly buffer Denom { uint denom[]; };
layout(std430, binding = DECIDE_BINDING_MAX_RADIUS) readonly buffer MaxRadius { float max_radius[]; };
layout(std430, binding = DECIDE_BINDING_PLANE_DISTANCE) readonly buffer PlaneDistance {
  float plane_distance[];
};
layout(push_constant) uniform Push { DensifyParams p; };

DensifyInput load_input(uint i) {
  DensifyInput g;
  bool finite = true;
  float max_log_scale = log_scales[3 * i];
  for (uint a = 0u; a < 3u; ++a) {
    finite = finite && finite_bits(means[3 * i + a]) && finite_bits(log_scales[3 * i + a]);
    max_log_scale = max(max_log_scale, log_scales[3 * i + a]);
  }
  for (uint a = 0u; a < 4u; ++a) finite = finite && finite_bits(quats[4 * i + a]);
  for (uint k = 0u; k < p.sh_values; ++k) finite = finite && finite_bits(sh[i * p.sh_values + k]);
  g.opacity_logit = opacity_logits[i];
  g.finite = finite && finite_bits(g.opacity_logit);
  g.max_log_scale = max_log_scale;
  g.grad_accum = grad_accum[i];
  g.denom = denom[i];
  g.max_radius = max_radius[i];
  g.plane_distance = (p.flags & DENSIFY_FLAG_PLANE_PRUNE) != 0u ? plane_distance[i] : 0.0;
  return g;
}
