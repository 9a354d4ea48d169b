#version 450
#extension GL_GOOGLE_include_directive : require
// Per Gaussian: gradients of the raw parameters from those of its projected quantities and colour.
#include "limits.h"
#include "elementwise.glsl"
#include "splat/splat_shared.h"
#include "splat/splat_math.h"
#include "splat/splat_view.glsl"

// The parameters and the gradient rows, read as texels (splat_shared.h): R32_SFLOAT, the quaternions
// R32G32B32A32_SFLOAT.
layout(binding = PBWD_BINDING_MEANS) uniform samplerBuffer means;
layout(binding = PBWD_BINDING_LOG_SCALES) uniform samplerBuffer log_scales;
layout(binding = PBWD_BINDING_QUATS) uniform samplerBuffer quats;
layout(binding = PBWD_BINDING_OPACITY_LOGITS) uniform samplerBuffer opacity_logits;
layout(binding = PBWD_BINDING_SH) uniform samplerBuffer sh;
layout(std430, binding = PBWD_BINDING_TILE_RECTS) readonly buffer Rects { uvec2 rects[]; };
#include "splat/tile_rect.glsl"
layout(binding = PBWD_BINDING_GRAD2D) uniform samplerBuffer grad2d;
layout(std430, binding = PBWD_BINDING_GRAD_MEANS) writeonly buffer GMeans { float g_means[]; };
layout(std430, binding = PBWD_BINDING_GRAD_LOG_SCALES) writeonly buffer GLogScales { float g_log_scales[]; };
layout(std430, binding = PBWD_BINDING_GRAD_QUATS) writeonly buffer GQuats { float g_quats[]; };
layout(std430, binding = PBWD_BINDING_GRAD_OPACITY_LOGITS) writeonly buffer GLogits { float g_logits[]; };
layout(std430, binding = PBWD_BINDING_GRAD_SH) writeonly buffer GSh { float g_sh[]; };
// 0: no SH gradient is stored (the optimizer computes it, kernels/optim/sh_adam.comp; g_sh is a dummy).
layout(constant_id = 2) const uint WRITE_SH_GRAD = 1;

void main() {
  const uint i = elementwise_index();
  if (i >= view.count) return;
  const uint K = view.sh_coeffs;
  const uvec4 r = unpack_tile_rect(rects[i]);
  if (r.z <= r.x) {  // culled: no gradient
    for (uint a = 0u; a < 3u; ++a) {
      g_means[3 * i + a] = 0.0;
      g_log_scales[3 * i + a] = 0.0;
    }
    for (uint a = 0u; a < 4u; ++a) g_quats[4 * i + a] = 0.0;
    g_logits[i] = 0.0;
    if (WRITE_SH_GRAD != 0u)
      for (uint k = 0u; k < K * CHANNELS; ++k) g_sh[i * K * CHANNELS + k] = 0.0;
    return;
  }
  const uint base = i * GRAD2D_STRIDE;
  ProjectedGrad pg;
  pg.mean2d = vec2(fetch1(grad2d, base), fetch1(grad2d, base + 1));
  pg.conic = vec3(fetch1(grad2d, base + 2), fetch1(grad2d, base + 3), fetch1(grad2d, base + 4));
  pg.opacity = fetch1(grad2d, base + 5);
  pg.depth = fetch1(grad2d, base + 6);

  const vec3 mean = fetch3(means, i);
  const vec3 log_scale = fetch3(log_scales, i);
  const vec4 quat = texelFetch(quats, int(i));
  const ParamGrad p =
      project_gaussian_backward(view_geometry(), mean, log_scale, quat, fetch1(opacity_logits, i), pg);

  // Colour = sum_k basis_k c_k + 0.5, clamped at 0; its direction depends on the mean.
  const vec3 ray = mean - camera_centre();
  const vec3 dir = normalize(ray);
  float basis[SPLAT_MAX_SH_COEFFS];
  sh_basis(view.sh_degree, dir, basis);
  float weights[SPLAT_MAX_SH_COEFFS];
  for (uint k = 0u; k < uint(SPLAT_MAX_SH_COEFFS); ++k) weights[k] = 0.0;
  for (uint c = 0u; c < CHANNELS; ++c) {
    const float g_color = fetch1(grad2d, base + SPLAT_GRAD2D_FIXED + c);
    float sum = 0.5;
    for (uint k = 0u; k < K; ++k) sum += basis[k] * fetch1(sh, (i * K + k) * CHANNELS + c);
    const bool clamped = sum < 0.0;
    for (uint k = 0u; k < K; ++k) {
      const uint idx = (i * K + k) * CHANNELS + c;
      if (WRITE_SH_GRAD != 0u) g_sh[idx] = clamped ? 0.0 : basis[k] * g_color;
      if (!clamped) weights[k] += g_color * fetch1(sh, idx);
    }
  }
  const vec3 ddir = sh_basis_dir_grad(view.sh_degree, dir, weights);
  const vec3 dray = (ddir - dir * dot(dir, ddir)) / length(ray);
  const vec3 gm = p.mean + dray;
  for (uint a = 0u; a < 3u; ++a) {
    g_means[3 * i + a] = gm[a];
    g_log_scales[3 * i + a] = p.log_scale[a];
  }
  for (uint a = 0u; a < 4u; ++a) g_quats[4 * i + a] = p.quat[a];
  g_logits[i] = p.opacity_logit;
}
