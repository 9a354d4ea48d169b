#version 450
#extension GL_GOOGLE_include_directive : require
// Per depth-sorted position: one (tile, intersection) pair per touched tile, in depth order, so that a
// stable sort by tile keeps every tile's list front to back. The rectangle was computed once, in project.
#include "limits.h"
#include "elementwise.glsl"
#include "splat/splat_shared.h"

layout(std430, binding = EMIT_BINDING_ORDER) readonly buffer Order { uint order[]; };
layout(std430, binding = EMIT_BINDING_TILE_RECTS) readonly buffer Rects { uvec2 rects[]; };
#include "splat/tile_rect.glsl"
layout(std430, binding = EMIT_BINDING_OFFSETS) readonly buffer Offsets { uint offsets[]; };
layout(std430, binding = EMIT_BINDING_TILE_KEYS) writeonly buffer TileKeys { uint tile_keys[]; };
layout(std430, binding = EMIT_BINDING_ISECT_IDS) writeonly buffer IsectIds { uint isect_ids[]; };
layout(std430, binding = EMIT_BINDING_ISECT_GAUSSIAN) writeonly buffer IsectGaussian {
  uint isect_gaussian[];
};
layout(push_constant) uniform Push { SplatView view; };

void main() {
  const uint s = elementwise_index();
  if (s >= view.count) return;
  const uint g = order[s];
  const uvec4 r = unpack_tile_rect(rects[g]);
  const uint first = offsets[s];
  const uint width = r.z - r.x, count = width * (r.w - r.y);
  // One do-while over the rectangle's tiles, not two nested for loops: a CPU driver runs every loop's body
  // once more, masked, when its test fails (nested: once per row and once more in all).
  uint t = 0u;
  if (count > 0u) do {
    const uint e = first + t;
    tile_keys[e] = (r.y + t / width) * view.tiles_x + r.x + t % width;
    isect_ids[e] = e;
    isect_gaussian[e] = g;
  } while (++t < count);
}
