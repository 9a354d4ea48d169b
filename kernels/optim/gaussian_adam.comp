#version 450
#extension GL_GOOGLE_include_directive : require
// One training step's parameter update, one invocation per Gaussian: the gradients of its raw parameters
// from the rasterizer's row (project_backward.comp's arithmetic, splat/param_gradients.glsl), 3DGS-MCMC's
// regularizers (mcmc_regularize.comp's terms), then Adam on every element (optim/adam_step.glsl, as
// adam.comp). Every gradient is computed from the parameters before this step, as the separate kernels see
// them. No parameter gradient is stored.
#include "limits.h"
#include "optim/optim_shared.h"
#include "elementwise.glsl"
#include "optim/adam_step.glsl"
#include "splat/splat_shared.h"
#include "splat/splat_math.h"

layout(std430, binding = GAUSSIAN_ADAM_BINDING_MEANS) buffer Means { float means[]; };
layout(std430, binding = GAUSSIAN_ADAM_BINDING_LOG_SCALES) buffer LogScales { float log_scales[]; };
layout(std430, binding = GAUSSIAN_ADAM_BINDING_QUATS) buffer Quats { float quats[]; };
layout(std430, binding = GAUSSIAN_ADAM_BINDING_OPACITY_LOGITS) buffer Logits { float opacity_logits[]; };
layout(std430, binding = GAUSSIAN_ADAM_BINDING_SH) buffer Sh { float sh[]; };
layout(std430, binding = GAUSSIAN_ADAM_BINDING_EXP_AVG + 0) buffer M0 { float m_means[]; };
layout(std430, binding = GAUSSIAN_ADAM_BINDING_EXP_AVG + 1) buffer M1 { float m_log_scales[]; };
layout(std430, binding = GAUSSIAN_ADAM_BINDING_EXP_AVG + 2) buffer M2 { float m_quats[]; };
layout(std430, binding = GAUSSIAN_ADAM_BINDING_EXP_AVG + 3) buffer M3 { float m_logits[]; };
layout(std430, binding = GAUSSIAN_ADAM_BINDING_EXP_AVG + 4) buffer M4 { float m_sh[]; };
layout(std430, binding = GAUSSIAN_ADAM_BINDING_EXP_AVG_SQ + 0) buffer V0 { float v_means[]; };
layout(std430, binding = GAUSSIAN_ADAM_BINDING_EXP_AVG_SQ + 1) buffer V1 { float v_log_scales[]; };
layout(std430, binding = GAUSSIAN_ADAM_BINDING_EXP_AVG_SQ + 2) buffer V2 { float v_quats[]; };
layout(std430, binding = GAUSSIAN_ADAM_BINDING_EXP_AVG_SQ + 3) buffer V3 { float v_logits[]; };
layout(std430, binding = GAUSSIAN_ADAM_BINDING_EXP_AVG_SQ + 4) buffer V4 { float v_sh[]; };
layout(std430, binding = GAUSSIAN_ADAM_BINDING_COUNTERS) buffer Counters { uint counters[]; };
layout(std430, binding = GAUSSIAN_ADAM_BINDING_TILE_RECTS) readonly buffer Rects { uvec2 rects[]; };
#include "splat/tile_rect.glsl"
// Read as texels: on CPU drivers a texel fetch at a per-lane index is one vector gather.
layout(binding = GAUSSIAN_ADAM_BINDING_GRAD2D) uniform samplerBuffer grad2d;
layout(push_constant) uniform Push { GaussianAdamParams p; };

layout(constant_id = 1) const uint CHANNELS = 1;  // the gradient rows' stride is SPLAT_GRAD2D_FIXED + C
layout(constant_id = 2) const float BETA1 = 0.9;
layout(constant_id = 3) const float BETA2 = 0.999;
layout(constant_id = 4) const float EPS = 1e-15;
const uint GRAD2D_STRIDE = SPLAT_GRAD2D_FIXED + CHANNELS;

vec3 param_mean(uint i) { return vec3(means[3 * i], means[3 * i + 1], means[3 * i + 2]); }
vec3 param_log_scale(uint i) { return vec3(log_scales[3 * i], log_scales[3 * i + 1], log_scales[3 * i + 2]); }
vec4 param_quat(uint i) { return vec4(quats[4 * i], quats[4 * i + 1], quats[4 * i + 2], quats[4 * i + 3]); }
float param_logit(uint i) { return opacity_logits[i]; }
float param_sh(uint j) { return sh[j]; }
float grad2d_value(uint j) { return texelFetch(grad2d, int(j)).x; }
#include "splat/param_gradients.glsl"

ViewGeometry view_geometry() {
  ViewGeometry v;
  v.R = mat3(p.rot[0], p.rot[1], p.rot[2], p.rot[3], p.rot[4], p.rot[5], p.rot[6], p.rot[7], p.rot[8]);
  v.t = vec3(p.trans[0], p.trans[1], p.trans[2]);
  v.fx = p.fx;
  v.fy = p.fy;
  v.cx = p.cx;
  v.cy = p.cy;
  v.near_m = p.near_m;
  v.width = float(p.width);
  v.height = float(p.height);
  return v;
}

AdamParams adam_params() {
  AdamParams a;
  a.count = p.count;
  a.period = 1u;
  a.lead = 1u;
  a.counter_slot = 0u;
  a.lr = 0.0;  // each group passes its own
  a.lr_rest = 0.0;
  a.reserved = 0u;
  a.beta1 = BETA1;
  a.beta2 = BETA2;
  a.eps = EPS;
  a.bias_correction1 = p.bias_correction1;
  a.sqrt_bias_correction2 = p.sqrt_bias_correction2;
  return a;
}

// One element's step; a non-finite gradient, moment or result leaves it and counts in the group's slot.
#define ADAM_ELEMENT(PARAM, M, V, J, G, LR, SLOT)                                      \
  {                                                                                    \
    float x = PARAM[J], m = M[J], v = V[J];                                            \
    if (adam_step_value(a, LR, G, x, m, v)) {                                          \
      PARAM[J] = x;                                                                    \
      M[J] = m;                                                                        \
      V[J] = v;                                                                        \
    } else {                                                                           \
      atomicAdd(counters[SLOT], 1u);                                                   \
    }                                                                                  \
  }

void main() {
  const uint i = elementwise_index();
  if (i >= p.count) return;
  const uint K = p.sh_coeffs;
  ParamGradients g = param_gradients(i, view_geometry(), p.sh_degree, K);
  const float o = 1.0 / (1.0 + exp(-opacity_logits[i]));
  g.logit += p.opacity_reg * o * (1.0 - o);  // d sigmoid / d logit
  for (uint k = 0u; k < 3u; ++k) g.log_scale[k] += p.scale_reg * exp(min(log_scales[3 * i + k], 20.0));

  const AdamParams a = adam_params();
  for (uint k = 0u; k < 3u; ++k) {
    ADAM_ELEMENT(means, m_means, v_means, 3 * i + k, g.mean[k], p.lr[0], 0u)
    ADAM_ELEMENT(log_scales, m_log_scales, v_log_scales, 3 * i + k, g.log_scale[k], p.lr[1], 1u)
  }
  for (uint k = 0u; k < 4u; ++k) ADAM_ELEMENT(quats, m_quats, v_quats, 4 * i + k, g.quat[k], p.lr[2], 2u)
  ADAM_ELEMENT(opacity_logits, m_logits, v_logits, i, g.logit, p.lr[3], 3u)
  // SH bands above the active degree are not stepped: their gradient is 0, and has been since training
  // began (the active degree only rises), so their moments are 0 and Adam's step would leave them exactly.
  const uint active_coeffs = min(K, (p.sh_degree + 1u) * (p.sh_degree + 1u));
  // do-while (active_coeffs >= 1): a CPU driver runs a for loop's body once more, masked, at its end.
  uint k = 0u;
  do {
    for (uint c = 0u; c < CHANNELS; ++c) {
      const uint j = (i * K + k) * CHANNELS + c;
      ADAM_ELEMENT(sh, m_sh, v_sh, j, g.basis[k] * g.color[c], k == 0u ? p.lr[4] : p.lr_sh_rest, 4u)
    }
  } while (++k < active_coeffs);
}
