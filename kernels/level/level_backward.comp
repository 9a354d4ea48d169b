#version 450
#extension GL_GOOGLE_include_directive : require
// The level model's backward (level_shared.h): the image gradient G g v, and block sums of the parameters'
// gradients (G g v x, G, G g x r^2, G g x r^4) in a fixed order: deterministic, no atomics.
#include "limits.h"
#include "level/level_shared.h"

layout(local_size_x = 256) in;
layout(std430, binding = LEVEL_BACKWARD_BINDING_IMAGE) readonly buffer Image { float image[]; };
layout(std430, binding = LEVEL_BACKWARD_BINDING_GRAD_LEVELED) readonly buffer GradLeveled {
  float grad_leveled[];
};
layout(std430, binding = LEVEL_BACKWARD_BINDING_STATE) readonly buffer State { float state[]; };
layout(std430, binding = LEVEL_BACKWARD_BINDING_GRAD_IMAGE) writeonly buffer GradImage {
  float grad_image[];
};
layout(std430, binding = LEVEL_BACKWARD_BINDING_SUMS) writeonly buffer Sums { vec4 sums[]; };
layout(push_constant) uniform Push { LevelParams p; };

#include "level/level_pixel.glsl"

shared vec4 partial[256];

void main() {
  const uint t = gl_LocalInvocationID.x;
  const uint begin = gl_WorkGroupID.x * uint(LEVEL_ROWS_PER_GROUP);
  const uint row = p.frame * LEVEL_STRIDE;
  const float gain = exp(state[row]);
  const uint shared_row = p.frames * LEVEL_STRIDE;
  const float k1 = p.vignetting != 0u ? state[shared_row] : 0.0;
  const float k2 = p.vignetting != 0u ? state[shared_row + 1] : 0.0;
  vec4 s = vec4(0.0);
  for (uint k = 0u; k < uint(LEVEL_ROWS_PER_THREAD); ++k) {
    const uint e = begin + k * 256u + t;
    if (e >= p.count) break;
    const float r2 = p.vignetting != 0u ? level_r2(e, p) : 0.0;
    const float v = level_vignetting(r2, k1, k2);
    const float g = grad_leveled[e];
    const float gx = g * gain * image[e];
    grad_image[e] = g * gain * v;
    s += vec4(gx * v, g, gx * r2, gx * (r2 * r2));
  }
  partial[t] = s;
  barrier();
  for (uint stride = 128u; stride > 0u; stride >>= 1u) {
    if (t < stride) partial[t] += partial[t + stride];
    barrier();
  }
  if (t == 0u) sums[gl_WorkGroupID.x] = partial[0];
}
