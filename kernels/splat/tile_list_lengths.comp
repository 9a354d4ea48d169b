#version 450
#extension GL_GOOGLE_include_directive : require
#extension GL_KHR_shader_subgroup_arithmetic : require
#extension GL_KHR_shader_subgroup_basic : require
// One workgroup: the 2D prefix sum of the corner difference grid (gather_counts.comp) gives every tile's list
// length; their maximum tells the host how many rasterize passes the longest list needs, before the
// intersections are emitted and sorted (so it rides in the forward's one readback).
#include "splat/splat_shared.h"

layout(local_size_x = LENGTHS_GROUP_SIZE) in;
layout(std430, binding = LENGTHS_BINDING_CORNERS) buffer Corners { uint corners[]; };
layout(std430, binding = LENGTHS_BINDING_COUNTERS) buffer Counters { uint counters[]; };
layout(push_constant) uniform Push { SplatView view; };

shared uint s_max[LENGTHS_GROUP_SIZE];

void main() {
  const uint row = view.tiles_x + 1u, rows = view.tiles_y + 1u;
  const uint t = gl_LocalInvocationIndex;
  for (uint y = t; y < rows; y += LENGTHS_GROUP_SIZE) {
    uint sum = 0u;
    for (uint x = 0u; x < row; ++x) {
      sum += corners[y * row + x];
      corners[y * row + x] = sum;
    }
  }
  memoryBarrierBuffer();
  barrier();
  uint longest = 0u;
  for (uint x = t; x < view.tiles_x; x += LENGTHS_GROUP_SIZE) {
    uint sum = 0u;
    for (uint y = 0u; y < view.tiles_y; ++y) {
      sum += corners[y * row + x];
      longest = max(longest, sum);
    }
  }
  s_max[t] = longest;
  barrier();
  if (t == 0u) {
    uint m = 0u;
    for (uint i = 0u; i < LENGTHS_GROUP_SIZE; ++i) m = max(m, s_max[i]);
    counters[SPLAT_COUNTER_MAX_LIST] = m;
  }
}
