#version 450
#extension GL_GOOGLE_include_directive : require
#include "common.glsl"
#include "sort/radix_sort_shared.h"
#include "sort/radix_digit_match.glsl"

layout(std430, binding = RADIX_SCATTER_BINDING_KEYS_IN) readonly buffer KeysIn { uint keys_in[]; };
layout(std430, binding = RADIX_SCATTER_BINDING_VALUES_IN) readonly buffer ValuesIn { uint values_in[]; };
layout(std430, binding = RADIX_SCATTER_BINDING_OFFSETS) readonly buffer Offsets { uint offsets[]; };
layout(std430, binding = RADIX_SCATTER_BINDING_KEYS_OUT) writeonly buffer KeysOut { uint keys_out[]; };
layout(std430, binding = RADIX_SCATTER_BINDING_VALUES_OUT) writeonly buffer ValuesOut { uint values_out[]; };
layout(push_constant) uniform Push { RadixPassParams p; };

// Next free destination of each digit for this block.
shared uint s_next[RADIX_BUCKETS];

void main() {
  const uint lane = gl_SubgroupInvocationID;
  for (uint d = lane; d < RADIX_BUCKETS; d += SUBGROUP_SIZE)
    s_next[d] = offsets[d * p.block_count + gl_WorkGroupID.x];
  subgroupMemoryBarrierShared();
  subgroupBarrier();

  const uint begin = gl_WorkGroupID.x * p.block_size;
  const uint end = min(begin + p.block_size, p.count);
  const uint mask = (1u << p.digit_bits) - 1u;
  // Batches go in input order and lanes within a batch rank by lane index: equal keys keep their order.
  for (uint base = begin; base < end; base += SUBGROUP_SIZE) {
    const uint i = base + lane;
    const bool in_range = i < end;
    const uint key = in_range ? keys_in[i] : 0u;
    const uint digit = (key >> p.shift) & mask;
    const uint first = s_next[digit];
    const uvec4 peers = lanes_with_same_digit(digit, in_range);
    const uint dst = first + peer_rank(peers);
    subgroupMemoryBarrierShared();
    subgroupBarrier();  // every lane has read s_next before the group's last lane advances it
    if (in_range) {
      keys_out[dst] = key;
      values_out[dst] = values_in[i];
      if (is_last_peer(peers)) s_next[digit] = first + peer_count(peers);
    }
    subgroupMemoryBarrierShared();
    subgroupBarrier();
  }
}
