#version 450
#extension GL_GOOGLE_include_directive : require
// Per Gaussian, after the Adam step: the SGLD noise of 3DGS-MCMC, shaped by the Gaussian's own covariance
// and gated to nearly transparent Gaussians: means += gate(opacity) * lr_means * noise_lr * Sigma * z.
#include "limits.h"
#include "elementwise.glsl"
#include "mcmc/mcmc_shared.h"
#include "splat/splat_shared.h"
#include "splat/splat_math.h"
#include "densify/densify_shared.h"
#include "densify/densify_math.h"
#include "mcmc/mcmc_math.h"

layout(std430, binding = NOISE_BINDING_MEANS) buffer Means { float means[]; };
layout(std430, binding = NOISE_BINDING_LOG_SCALES) readonly buffer LogScales { float log_scales[]; };
layout(std430, binding = NOISE_BINDING_QUATS) readonly buffer Quats { float quats[]; };
layout(std430, binding = NOISE_BINDING_OPACITY_LOGITS) readonly buffer Logits { float opacity_logits[]; };
layout(push_constant) uniform Push { McmcParams p; };

void main() {
  const uint i = elementwise_index();
  if (i >= p.count) return;
  const vec3 log_scale = vec3(log_scales[3 * i], log_scales[3 * i + 1], log_scales[3 * i + 2]);
  const vec4 quat = vec4(quats[4 * i], quats[4 * i + 1], quats[4 * i + 2], quats[4 * i + 3]);
  const vec3 offset = covariance_world(log_scale, quat) * noise_normals(p.seed, p.step, i) *
                    (noise_gate(opacity_logits[i]) * p.noise_scale);
  if (!is_finite3(offset)) return;  // a non-finite row is relocated at the next refinement, never moved
  for (uint k = 0u; k < 3u; ++k) means[3 * i + k] += offset[k];
}
