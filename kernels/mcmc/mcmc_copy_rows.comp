#version 450
#extension GL_GOOGLE_include_directive : require
// Per target: one attribute buffer's row copied from the target's source, or a row zeroed (the moments of
// relocated rows restart, as 3DGS-MCMC resets them).
#include "limits.h"
#include "elementwise.glsl"
#include "mcmc/mcmc_shared.h"

layout(std430, binding = COPY_BINDING_SOURCE) readonly buffer Source { uint source[]; };
layout(std430, binding = COPY_BINDING_TARGET) readonly buffer Target { uint target[]; };
layout(std430, binding = COPY_BINDING_ROWS) buffer Rows { uint rows[]; };
layout(push_constant) uniform Push { CopyRowsParams p; };

void main() {
  const uint t = elementwise_index();
  if (t >= p.targets) return;
  const uint s = source[t] * p.stride;
  const uint d = (p.mode == COPY_MODE_ZERO_SOURCE ? source[t] : target[t]) * p.stride;
  for (uint k = 0u; k < p.stride; ++k) rows[d + k] = p.mode == COPY_MODE_SOURCE_TO_TARGET ? rows[s + k] : 0u;
}
