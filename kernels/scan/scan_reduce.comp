#version 450
#extension GL_GOOGLE_include_directive : require
#include "common.glsl"
#include "scan/scan_shared.h"

layout(std430, binding = SCAN_REDUCE_BINDING_DATA) readonly buffer Data { uint data[]; };
layout(std430, binding = SCAN_REDUCE_BINDING_BLOCK_SUMS) writeonly buffer BlockSums { uint block_sums[]; };
layout(push_constant) uniform Push { ScanParams p; };

void main() {
  const uint begin = gl_WorkGroupID.x * p.block_size;
  const uint end = min(begin + p.block_size, p.count);
  // Each lane sums a strided slice; one subgroup reduction at the end (no shared memory, no barrier).
  uint sum = 0u;
  for (uint i = begin + gl_SubgroupInvocationID; i < end; i += SUBGROUP_SIZE) sum += data[i];
  sum = subgroupAdd(sum);
  if (subgroupElect()) block_sums[gl_WorkGroupID.x] = sum;
}
