#version 450
#extension GL_GOOGLE_include_directive : require
#include "common.glsl"
#include "scan/scan_shared.h"

layout(std430, binding = SCAN_DOWNSWEEP_BINDING_DATA) buffer Data { uint data[]; };
layout(std430, binding = SCAN_DOWNSWEEP_BINDING_BLOCK_OFFSETS) readonly buffer BlockOffsets {
  uint block_offsets[];
};
layout(push_constant) uniform Push { ScanParams p; };

void main() {
  const uint begin = gl_WorkGroupID.x * p.block_size;
  const uint end = min(begin + p.block_size, p.count);
  uint carry = p.use_block_offsets != 0u ? block_offsets[gl_WorkGroupID.x] : 0u;
  // The block is walked in order, one subgroup-wide batch at a time, carrying the running total.
  for (uint base = begin; base < end; base += SUBGROUP_SIZE) {
    const uint i = base + gl_SubgroupInvocationID;
    const uint v = i < end ? data[i] : 0u;
    const uint exclusive = subgroupExclusiveAdd(v);
    if (i < end) data[i] = carry + exclusive;
    carry += subgroupAdd(v);
  }
}
