#version 450
#extension GL_GOOGLE_include_directive : require
// Adam on the SH coefficients, each Gaussian's gradient computed here from the colour gradient the
// rasterizer left in its per-Gaussian row, rather than read from a stored [N][K][C] gradient (64 B per
// Gaussian at degree 3 and one channel). The gradient is project_backward's: colour = sum_k basis_k(dir) c_k
// + 0.5, clamped at 0, with dir from the camera centre to the mean; none for a culled Gaussian. The step is
// adam.comp's (optim/adam_step.glsl), element for element.
#include "limits.h"
#include "optim/optim_shared.h"
#include "elementwise.glsl"
#include "optim/adam_step.glsl"
#include "splat/splat_shared.h"
#include "splat/splat_math.h"

layout(std430, binding = SH_ADAM_BINDING_SH) buffer Sh { float sh[]; };
layout(std430, binding = SH_ADAM_BINDING_EXP_AVG) buffer ExpAvg { float exp_avg[]; };
layout(std430, binding = SH_ADAM_BINDING_EXP_AVG_SQ) buffer ExpAvgSq { float exp_avg_sq[]; };
layout(std430, binding = SH_ADAM_BINDING_COUNTERS) buffer Counters { uint counters[]; };
layout(std430, binding = SH_ADAM_BINDING_MEANS) readonly buffer Means { float means[]; };
layout(std430, binding = SH_ADAM_BINDING_TILE_RECTS) readonly buffer Rects { uvec2 rects[]; };
#include "splat/tile_rect.glsl"
layout(std430, binding = SH_ADAM_BINDING_GRAD2D) readonly buffer Grad2d { float grad2d[]; };
layout(push_constant) uniform Push { ShAdamParams p; };

// Model channel count, as in the rasterizer's kernels: the stride of the gradient rows.
layout(constant_id = 1) const uint CHANNELS = 1;

void adam_step(uint j, float g, float lr) {
  float x = sh[j], m = exp_avg[j], v = exp_avg_sq[j];
  if (!adam_step_value(p.adam, lr, g, x, m, v)) {
    atomicAdd(counters[p.adam.counter_slot], 1u);
    return;
  }
  exp_avg[j] = m;
  exp_avg_sq[j] = v;
  sh[j] = x;
}

void main() {
  const uint i = elementwise_index();
  if (i >= p.adam.count) return;
  const uint K = p.sh_coeffs;
  const uvec4 r = unpack_tile_rect(rects[i]);
  const bool culled = r.z <= r.x;
  const vec3 mean = vec3(means[3 * i], means[3 * i + 1], means[3 * i + 2]);
  const vec3 dir = normalize(mean - vec3(p.centre[0], p.centre[1], p.centre[2]));
  float basis[SPLAT_MAX_SH_COEFFS];
  sh_basis(p.sh_degree, dir, basis);
  const uint row = i * (SPLAT_GRAD2D_FIXED + CHANNELS);
  for (uint c = 0u; c < CHANNELS; ++c) {
    // The clamp is decided on the coefficients before this step, as the backward saw them.
    float sum = 0.5;
    for (uint k = 0u; k < K; ++k) sum += basis[k] * sh[(i * K + k) * CHANNELS + c];
    const bool pass = !culled && sum >= 0.0;
    const float g_color = grad2d[row + SPLAT_GRAD2D_FIXED + c];
    for (uint k = 0u; k < K; ++k)
      adam_step((i * K + k) * CHANNELS + c, pass ? basis[k] * g_color : 0.0,
                k == 0u ? p.adam.lr : p.adam.lr_rest);
  }
}
