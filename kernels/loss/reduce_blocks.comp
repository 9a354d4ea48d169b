#version 450
#extension GL_GOOGLE_include_directive : require
// Block sums of vec2 rows in a fixed order (loss_shared.h): deterministic, no atomics.
#include "limits.h"
#include "loss/loss_shared.h"

layout(local_size_x = 256) in;
layout(std430, binding = REDUCE_BLOCKS_BINDING_ROWS) readonly buffer Rows { vec2 rows[]; };
layout(std430, binding = REDUCE_BLOCKS_BINDING_SUMS) writeonly buffer Sums { vec2 sums[]; };
layout(push_constant) uniform Push { ReduceParams p; };

shared vec2 partial[256];

void main() {
  const uint t = gl_LocalInvocationID.x;
  const uint begin = gl_WorkGroupID.x * uint(LOSS_REDUCE_ROWS_PER_GROUP);
  vec2 s = vec2(0.0);
  for (uint k = 0u; k < uint(LOSS_REDUCE_ROWS_PER_THREAD); ++k) {
    const uint i = begin + k * 256u + t;
    if (i < p.count) s += rows[i];
  }
  partial[t] = s;
  barrier();
  for (uint stride = 128u; stride > 0u; stride >>= 1u) {
    if (t < stride) partial[t] += partial[t + stride];
    barrier();
  }
  if (t == 0u) sums[gl_WorkGroupID.x] = partial[0];
}
