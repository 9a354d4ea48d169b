#version 450
#extension GL_GOOGLE_include_directive : require
#include "common.glsl"
#include "sort/radix_sort_shared.h"
#include "sort/radix_digit_match.glsl"

layout(std430, binding = RADIX_HISTOGRAM_BINDING_KEYS) readonly buffer Keys { uint keys[]; };
layout(std430, binding = RADIX_HISTOGRAM_BINDING_COUNTS) writeonly buffer Counts { uint counts[]; };
layout(push_constant) uniform Push { RadixPassParams p; };

shared uint s_count[RADIX_BUCKETS];

void main() {
  const uint lane = gl_SubgroupInvocationID;
  for (uint d = lane; d < RADIX_BUCKETS; d += SUBGROUP_SIZE) s_count[d] = 0u;
  subgroupMemoryBarrierShared();
  subgroupBarrier();

  const uint begin = gl_WorkGroupID.x * p.block_size;
  const uint end = min(begin + p.block_size, p.count);
  const uint mask = (1u << p.digit_bits) - 1u;
  for (uint base = begin; base < end; base += SUBGROUP_SIZE) {
    const uint i = base + lane;
    const bool in_range = i < end;
    const uint digit = in_range ? (keys[i] >> p.shift) & mask : 0u;
    const uvec4 peers = lanes_with_same_digit(digit, in_range);
    // One lane per distinct digit (the highest) adds the group's size: no two lanes touch one counter.
    if (in_range && is_last_peer(peers)) s_count[digit] += peer_count(peers);
    subgroupMemoryBarrierShared();
    subgroupBarrier();
  }

  for (uint d = lane; d < RADIX_BUCKETS; d += SUBGROUP_SIZE)
    counts[d * p.block_count + gl_WorkGroupID.x] = s_count[d];
}
