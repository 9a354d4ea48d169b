#version 450
#extension GL_GOOGLE_include_directive : require
// Per sorted intersection: the record the per-pixel passes read (splat_shared.h, list_entry.glsl), in list
// order, with the 1/255 extent computed once per entry rather than once per subgroup that walks it.
#include "limits.h"
#include "elementwise.glsl"
#include "splat/splat_shared.h"
#include "splat/splat_math.h"
#include "splat/splat_view.glsl"
#include "splat/footprint.glsl"
#include "splat/list_entry.glsl"

layout(std430, binding = PACK_BINDING_ISECT_IDS) readonly buffer IsectIds { uint isect_ids[]; };
layout(std430, binding = PACK_BINDING_ISECT_GAUSSIAN) readonly buffer IsectGaussian { uint isect_gaussian[]; };
layout(std430, binding = PACK_BINDING_MEANS2D) readonly buffer Means2d { float means2d[]; };
layout(std430, binding = PACK_BINDING_CONICS) readonly buffer Conics { float conics[]; };
layout(std430, binding = PACK_BINDING_DEPTHS) readonly buffer Depths { float depths[]; };
layout(std430, binding = PACK_BINDING_OPACITIES) readonly buffer Opacities { float opacities[]; };
layout(std430, binding = PACK_BINDING_COLORS) readonly buffer Colors { float colors[]; };
layout(std430, binding = PACK_BINDING_ENTRIES) writeonly buffer Entries { vec4 entries[]; };

void main() {
  const uint i = elementwise_index();
  if (i >= view.count) return;
  const uint g = isect_gaussian[isect_ids[i]];
  const vec3 conic = vec3(conics[3 * g], conics[3 * g + 1], conics[3 * g + 2]);
  const float opacity = opacities[g];
  float tail[8];
  for (uint j = 0u; j < 8u; ++j) tail[j] = 0.0;
  for (uint c = 0u; c < CHANNELS; ++c) tail[c] = colors[g * CHANNELS + c];
  tail[CHANNELS] = depths[g];
  tail[CHANNELS + 1u] = uintBitsToFloat(g);
  const uint base = i * ENTRY_VEC4S;
  entries[base] = vec4(means2d[2 * g], means2d[2 * g + 1], alpha_extent(conic, opacity));
  entries[base + 1u] = vec4(conic, opacity);
  entries[base + 2u] = vec4(tail[0], tail[1], tail[2], tail[3]);
  if (ENTRY_VEC4S > 3u) entries[base + 3u] = vec4(tail[4], tail[5], tail[6], tail[7]);
}
