#version 450
#extension GL_GOOGLE_include_directive : require
// One workgroup: the sum of the block sums in a fixed order, then the loss outputs (loss_shared.h).
#include "limits.h"
#include "loss/loss_shared.h"

layout(local_size_x = 256) in;
layout(std430, binding = REDUCE_FINISH_BINDING_SUMS) readonly buffer Sums { vec2 sums[]; };
layout(std430, binding = REDUCE_FINISH_BINDING_OUT) buffer Out { float out_values[]; };
layout(push_constant) uniform Push { ReduceParams p; };

shared vec2 partial[256];

void main() {
  const uint t = gl_LocalInvocationID.x;
  vec2 s = vec2(0.0);
  // p.count <= 256 * MAX_BATCHES_PER_WORKGROUP (checked on the host), within lavapipe's loop budget.
  for (uint i = t; i < p.count; i += 256u) s += sums[i];
  partial[t] = s;
  barrier();
  for (uint stride = 128u; stride > 0u; stride >>= 1u) {
    if (t < stride) partial[t] += partial[t + stride];
    barrier();
  }
  if (t == 0u) {
    const vec2 total = partial[0];
    out_values[p.slot] = p.bias0 + p.w00 * total.x + p.w01 * total.y;
    if (p.outputs >= 2u) out_values[p.slot + 1u] = p.bias1 + p.w10 * total.x + p.w11 * total.y;
    if (p.outputs >= 3u) out_values[p.slot + 2u] = p.bias2 + p.w20 * total.x + p.w21 * total.y;
  }
}
