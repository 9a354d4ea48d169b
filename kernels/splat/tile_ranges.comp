#version 450
#extension GL_GOOGLE_include_directive : require
// Per sorted intersection: where each tile's list starts and ends (tiles with no entry stay [0, 0)).
#include "limits.h"
#include "elementwise.glsl"
#include "splat/splat_shared.h"

layout(std430, binding = RANGES_BINDING_TILE_KEYS) readonly buffer TileKeys { uint tile_keys[]; };
layout(std430, binding = RANGES_BINDING_RANGES) buffer Ranges { uvec2 ranges[]; };
layout(push_constant) uniform Push { SplatView view; };

void main() {
  const uint i = elementwise_index();
  const uint m = view.count;
  if (i >= m) return;
  const uint key = tile_keys[i];
  if (i == 0u || tile_keys[i - 1u] != key) ranges[key].x = i;
  if (i + 1u == m || tile_keys[i + 1u] != key) ranges[key].y = i + 1u;
}
