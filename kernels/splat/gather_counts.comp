#version 450
#extension GL_GOOGLE_include_directive : require
#extension GL_KHR_shader_subgroup_arithmetic : require
#extension GL_KHR_shader_subgroup_basic : require
// Per depth-sorted position: how many tiles that Gaussian touches (0 when culled); the exact total of all
// counts (two words: the scan of the counts wraps at 2^32, so its last value cannot be trusted for the
// total); and the rectangle's corners in the 2D difference grid whose prefix sum is each tile's list length.
#include "limits.h"
#include "elementwise.glsl"
#include "splat/splat_shared.h"

layout(std430, binding = GATHER_BINDING_ORDER) readonly buffer Order { uint order[]; };
layout(std430, binding = GATHER_BINDING_TILE_RECTS) readonly buffer Rects { uvec2 rects[]; };
#include "splat/tile_rect.glsl"
layout(std430, binding = GATHER_BINDING_COUNTS) writeonly buffer Counts { uint counts[]; };
layout(std430, binding = GATHER_BINDING_CORNERS) buffer Corners { uint corners[]; };
layout(std430, binding = GATHER_BINDING_COUNTERS) buffer Counters { uint counters[]; };
layout(push_constant) uniform Push { SplatView view; };

void main() {
  const uint s = elementwise_index();
  uint count = 0u;
  if (s < view.count) {
    const uvec4 r = unpack_tile_rect(rects[order[s]]);
    count = (r.z - r.x) * (r.w - r.y);
    counts[s] = count;
    if (count > 0u) {
      // Corner differences wrap modulo 2^32; the prefix sums come out exact (each length is below 2^32).
      const uint row = view.tiles_x + 1u;
      atomicAdd(corners[r.y * row + r.x], 1u);
      atomicAdd(corners[r.y * row + r.z], 0xFFFFFFFFu);
      atomicAdd(corners[r.w * row + r.x], 0xFFFFFFFFu);
      atomicAdd(corners[r.w * row + r.z], 1u);
    }
  }
  // One add per subgroup into a two-word total: a carry is counted whenever the low word wraps. A subgroup's
  // sum stays below 2^32 because the host bounds the tile count (Rasterizer::forward).
  const uint sum = subgroupAdd(count);
  if (subgroupElect() && sum > 0u) {
    const uint before = atomicAdd(counters[SPLAT_COUNTER_ISECT_LO], sum);
    if (before + sum < before) atomicAdd(counters[SPLAT_COUNTER_ISECT_HI], 1u);
  }
}
