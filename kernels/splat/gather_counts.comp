#version 450
#extension GL_GOOGLE_include_directive : require
// Per depth-sorted position: how many tiles that Gaussian touches (0 when culled).
#include "limits.h"
#include "splat/splat_shared.h"

layout(local_size_x = ELEMENTWISE_GROUP_SIZE) in;
layout(std430, binding = GATHER_BINDING_ORDER) readonly buffer Order { uint order[]; };
layout(std430, binding = GATHER_BINDING_TILE_RECTS) readonly buffer Rects { uvec4 rects[]; };
layout(std430, binding = GATHER_BINDING_COUNTS) writeonly buffer Counts { uint counts[]; };
layout(push_constant) uniform Push { SplatView view; };

void main() {
  const uint s = gl_GlobalInvocationID.x;
  if (s >= view.count) return;
  const uvec4 r = rects[order[s]];
  counts[s] = (r.z - r.x) * (r.w - r.y);
}
