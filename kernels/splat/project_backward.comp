#version 450
#extension GL_GOOGLE_include_directive : require
// Per Gaussian: gradients of the raw parameters from those of its projected quantities and colour
// (splat/param_gradients.glsl), stored for the optimizer's separate steps and the tests.
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

vec3 param_mean(uint i) { return fetch3(means, i); }
vec3 param_log_scale(uint i) { return fetch3(log_scales, i); }
vec4 param_quat(uint i) { return texelFetch(quats, int(i)); }
float param_logit(uint i) { return fetch1(opacity_logits, i); }
float param_sh(uint j) { return fetch1(sh, j); }
float grad2d_value(uint j) { return fetch1(grad2d, j); }
#include "splat/param_gradients.glsl"

void main() {
  const uint i = elementwise_index();
  if (i >= view.count) return;
  const uint K = view.sh_coeffs;
  const ParamGradients g = param_gradients(i, view_geometry(), view.sh_degree, K);
  for (uint c = 0u; c < CHANNELS; ++c)
    for (uint k = 0u; k < K; ++k) g_sh[(i * K + k) * CHANNELS + c] = g.basis[k] * g.color[c];
  for (uint a = 0u; a < 3u; ++a) {
    g_means[3 * i + a] = g.mean[a];
    g_log_scales[3 * i + a] = g.log_scale[a];
  }
  for (uint a = 0u; a < 4u; ++a) g_quats[4 * i + a] = g.quat[a];
  g_logits[i] = g.logit;
}
