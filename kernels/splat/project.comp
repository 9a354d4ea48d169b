#version 450
#extension GL_GOOGLE_include_directive : require
// Per Gaussian: projection, culling, colour from SH, the tile rectangle and the depth sort key.
#include "limits.h"
#include "elementwise.glsl"
#include "splat/splat_shared.h"
#include "splat/splat_math.h"
#include "splat/splat_view.glsl"
#include "splat/footprint.glsl"


layout(std430, binding = PROJECT_BINDING_MEANS) readonly buffer Means { float means[]; };
layout(std430, binding = PROJECT_BINDING_LOG_SCALES) readonly buffer LogScales { float log_scales[]; };
layout(std430, binding = PROJECT_BINDING_QUATS) readonly buffer Quats { float quats[]; };
layout(std430, binding = PROJECT_BINDING_OPACITY_LOGITS) readonly buffer Logits { float opacity_logits[]; };
layout(std430, binding = PROJECT_BINDING_SH) readonly buffer Sh { float sh[]; };
layout(std430, binding = PROJECT_BINDING_CENTRES) writeonly buffer Centres { vec4 centres[]; };
layout(std430, binding = PROJECT_BINDING_CONICS) writeonly buffer Conics { vec4 conics[]; };
layout(std430, binding = PROJECT_BINDING_COLORS) writeonly buffer Colors { float colors[]; };
layout(std430, binding = PROJECT_BINDING_TILE_RECTS) writeonly buffer Rects { uvec2 rects[]; };
#include "splat/tile_rect.glsl"
layout(std430, binding = PROJECT_BINDING_DEPTH_KEYS) writeonly buffer DepthKeys { uint depth_keys[]; };
layout(std430, binding = PROJECT_BINDING_ORDER) writeonly buffer Order { uint order[]; };
layout(std430, binding = PROJECT_BINDING_COUNTERS) buffer Counters { uint counters[]; };

void main() {
  const uint i = elementwise_index();
  if (i >= view.count) return;
  const vec3 mean = vec3(means[3 * i], means[3 * i + 1], means[3 * i + 2]);
  const vec3 log_scale = vec3(log_scales[3 * i], log_scales[3 * i + 1], log_scales[3 * i + 2]);
  const vec4 quat = vec4(quats[4 * i], quats[4 * i + 1], quats[4 * i + 2], quats[4 * i + 3]);
  const Projected pr = project_gaussian(view_geometry(), mean, log_scale, quat, opacity_logits[i]);
  bool sh_finite = true;
  for (uint k = 0u; k < view.sh_coeffs * CHANNELS; ++k)
    sh_finite = sh_finite && is_finite_real(sh[i * view.sh_coeffs * CHANNELS + k]);
  if (!pr.finite || !sh_finite) atomicAdd(counters[SPLAT_COUNTER_CULLED_NONFINITE], 1u);

  uvec4 rect = uvec4(0u);
  if (pr.visible && sh_finite) {
    const float T = float(SPLAT_TILE_SIZE);
    const vec2 lo = floor((pr.mean2d - pr.extent) / T);
    const vec2 hi = floor((pr.mean2d + pr.extent) / T) + 1.0;
    const vec2 grid = vec2(float(view.tiles_x), float(view.tiles_y));
    rect = uvec4(clamp(lo, vec2(0.0), grid), clamp(hi, vec2(0.0), grid));
    if (rect.x >= rect.z || rect.y >= rect.w) rect = uvec4(0u);
  }
  const bool kept = rect.z > rect.x;
  rects[i] = pack_tile_rect(rect);
  order[i] = i;
  // Camera z >= near > 0: the bits of a positive float sort like the float. Culled Gaussians go last.
  depth_keys[i] = kept ? floatBitsToUint(pr.depth) : 0xFFFFFFFFu;
  centres[i] = vec4(pr.mean2d, pr.depth, pr.opacity);
  conics[i] = vec4(pr.conic, alpha_reach(pr.opacity));

  float basis[SPLAT_MAX_SH_COEFFS];
  sh_basis(view.sh_degree, normalize(mean - camera_centre()), basis);
  for (uint c = 0u; c < CHANNELS; ++c) {
    float sum = 0.5;
    if (kept)
      for (uint k = 0u; k < view.sh_coeffs; ++k)
        sum += basis[k] * sh[(i * view.sh_coeffs + k) * CHANNELS + c];
    colors[i * CHANNELS + c] = max(sum, 0.0);
  }
}
