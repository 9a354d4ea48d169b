#version 450
#extension GL_GOOGLE_include_directive : require
// x' = g v x + o for the frame p.frame (level_shared.h), one element per invocation.
#include "limits.h"
#include "level/level_shared.h"
#include "elementwise.glsl"

layout(std430, binding = LEVEL_APPLY_BINDING_IMAGE) readonly buffer Image { float image[]; };
layout(std430, binding = LEVEL_APPLY_BINDING_STATE) readonly buffer State { float state[]; };
layout(std430, binding = LEVEL_APPLY_BINDING_OUT) writeonly buffer Out { float leveled[]; };
layout(push_constant) uniform Push { LevelParams p; };

#include "level/level_pixel.glsl"

void main() {
  const uint e = elementwise_index();
  if (e >= p.count) return;
  const uint row = p.frame * LEVEL_STRIDE;
  const float gain = exp(state[row]);
  float v = 1.0;
  if (p.vignetting != 0u) {
    const uint shared_row = p.frames * LEVEL_STRIDE;
    v = level_vignetting(level_r2(e, p), state[shared_row], state[shared_row + 1]);
  }
  leveled[e] = gain * v * image[e] + state[row + 1];
}
