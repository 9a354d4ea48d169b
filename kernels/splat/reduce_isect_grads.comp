#version 450
#extension GL_GOOGLE_include_directive : require
// Deterministic mode: per depth-sorted position, sum the Gaussian's intersection rows in emission order.
#include "limits.h"
#include "elementwise.glsl"
#include "splat/splat_shared.h"
#include "splat/splat_math.h"
#include "splat/splat_view.glsl"

layout(std430, binding = REDUCE_BINDING_ORDER) readonly buffer Order { uint order[]; };
layout(std430, binding = REDUCE_BINDING_OFFSETS) readonly buffer Offsets { uint offsets[]; };
layout(std430, binding = REDUCE_BINDING_ISECT_GRADS) readonly buffer IsectGrads { float isect_grads[]; };
layout(std430, binding = REDUCE_BINDING_GRAD2D) writeonly buffer Grad2d { float grad2d[]; };

void main() {
  const uint s = elementwise_index();
  if (s >= view.count) return;
  const uint g = order[s];
  const uint first = offsets[s], n = offsets[s + 1u] - first;  // modulo 2^32, as the scan
  float total[SPLAT_GRAD2D_FIXED + SPLAT_MAX_CHANNELS];
  for (uint k = 0u; k < GRAD2D_STRIDE; ++k) total[k] = 0.0;
  for (uint e = first; e < first + n; ++e)
    for (uint k = 0u; k < GRAD2D_STRIDE; ++k) total[k] += isect_grads[e * GRAD2D_STRIDE + k];
  for (uint k = 0u; k < GRAD2D_STRIDE; ++k) grad2d[g * GRAD2D_STRIDE + k] = total[k];
}
