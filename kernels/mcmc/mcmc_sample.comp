#version 450
#extension GL_GOOGLE_include_directive : require
// Per target row (the dead rows, then the rows added after N): draw a source in proportion to opacity by
// binary search of the weights' CDF, and count the draws of each source.
#include "limits.h"
#include "elementwise.glsl"
#include "mcmc/mcmc_shared.h"
#include "densify/densify_shared.h"
#include "densify/densify_math.h"

layout(std430, binding = SAMPLE_BINDING_CDF) readonly buffer Cdf { uint cdf[]; };
layout(std430, binding = SAMPLE_BINDING_DEAD_INDEX) readonly buffer DeadIndex { uint dead_index[]; };
layout(std430, binding = SAMPLE_BINDING_SOURCE) writeonly buffer Source { uint source[]; };
layout(std430, binding = SAMPLE_BINDING_TARGET) writeonly buffer Target { uint target[]; };
layout(std430, binding = SAMPLE_BINDING_COPIES) buffer Copies { uint copies[]; };
layout(push_constant) uniform Push { McmcParams p; };

void main() {
  const uint t = elementwise_index();
  if (t >= p.targets) return;
  // A draw in [0, total): the high word of a 32-bit hash times the total.
  uint u, low;
  umulExtended(pcg_hash(pcg_hash(pcg_hash(p.seed) ^ p.step) ^ t), p.total_weight, u, low);
  // The largest i with cdf[i] <= u: cdf is the exclusive scan, so that row's weight is > 0 (alive).
  uint lo = 0u, hi = p.count;  // cdf[lo] <= u < cdf[hi] (cdf[count] = total)
  while (hi - lo > 1u) {
    const uint mid = (lo + hi) / 2u;
    if (cdf[mid] <= u) lo = mid; else hi = mid;
  }
  source[t] = lo;
  target[t] = t < p.dead ? dead_index[t] : p.count + (t - p.dead);
  atomicAdd(copies[lo], 1u);
}
