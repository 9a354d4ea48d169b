#version 450
#extension GL_GOOGLE_include_directive : require
// Per Gaussian: the list of dead rows, in index order (stream compaction by the scanned dead flags).
#include "limits.h"
#include "elementwise.glsl"
#include "mcmc/mcmc_shared.h"

layout(std430, binding = LIST_BINDING_DEAD) readonly buffer Dead { uint dead[]; };
layout(std430, binding = LIST_BINDING_DEAD_RANK) readonly buffer DeadRank { uint dead_rank[]; };
layout(std430, binding = LIST_BINDING_DEAD_INDEX) writeonly buffer DeadIndex { uint dead_index[]; };
layout(push_constant) uniform Push { McmcParams p; };

void main() {
  const uint i = elementwise_index();
  if (i >= p.count || dead[i] == 0u) return;
  dead_index[dead_rank[i]] = i;
}
