#version 450
#extension GL_GOOGLE_include_directive : require
// Per Gaussian: projection, culling, colour from SH, the tile rectangle and the depth sort key.
#include "limits.h"
#include "elementwise.glsl"
#include "splat/splat_shared.h"
#include "splat/splat_math.h"
#include "splat/splat_view.glsl"
#include "splat/footprint.glsl"


// The parameters, read as texels (splat_shared.h): R32_SFLOAT, the quaternions R32G32B32A32_SFLOAT.
layout(binding = PROJECT_BINDING_MEANS) uniform samplerBuffer means;
layout(binding = PROJECT_BINDING_LOG_SCALES) uniform samplerBuffer log_scales;
layout(binding = PROJECT_BINDING_QUATS) uniform samplerBuffer quats;
layout(binding = PROJECT_BINDING_OPACITY_LOGITS) uniform samplerBuffer opacity_logits;
layout(binding = PROJECT_BINDING_SH) uniform samplerBuffer sh;
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
  const vec3 mean = fetch3(means, i);
  const vec3 log_scale = fetch3(log_scales, i);
  const vec4 quat = texelFetch(quats, int(i));
  const Projected pr = project_gaussian(view_geometry(), mean, log_scale, quat, fetch1(opacity_logits, i));
  // One pass over the SH coefficients: their finiteness and the colour sums (used only if the Gaussian is
  // kept, so a non-finite coefficient never reaches a colour).
  float basis[SPLAT_MAX_SH_COEFFS];
  sh_basis(view.sh_degree, normalize(mean - camera_centre()), basis);
  bool sh_finite = true;
  vec4 sums = vec4(0.5);
  for (uint c = 0u; c < CHANNELS; ++c)
    for (uint k = 0u; k < view.sh_coeffs; ++k) {
      const float v = fetch1(sh, (i * view.sh_coeffs + k) * CHANNELS + c);
      sh_finite = sh_finite && is_finite_real(v);
      sums[c] += basis[k] * v;
    }
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

  for (uint c = 0u; c < CHANNELS; ++c) colors[i * CHANNELS + c] = max(kept ? sums[c] : 0.5, 0.0);
}
