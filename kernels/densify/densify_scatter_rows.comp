#version 450
#extension GL_GOOGLE_include_directive : require
// Per Gaussian: write its rows of one attribute buffer at its scanned offset (stream compaction). The
// original (slot A of keep and clone) is copied; new rows (clone copies, split children) are copied or,
// for optimizer moments and statistics, zeroed.
#include "limits.h"
#include "elementwise.glsl"
#include "densify/densify_shared.h"

layout(std430, binding = SCATTER_BINDING_DECISION) readonly buffer Decision { uint decision[]; };
layout(std430, binding = SCATTER_BINDING_OFFSETS) readonly buffer Offsets { uint offsets[]; };
layout(std430, binding = SCATTER_BINDING_SRC) readonly buffer Src { uint src[]; };
layout(std430, binding = SCATTER_BINDING_DST) writeonly buffer Dst { uint dst[]; };
layout(push_constant) uniform Push { ScatterParams p; };

void write_row(uint from, uint to, bool zero) {
  for (uint w = 0u; w < p.stride; ++w) dst[to * p.stride + w] = zero ? 0u : src[from * p.stride + w];
}

void main() {
  const uint i = elementwise_index();
  if (i >= p.count) return;
  const uint d = decision[i];
  const uint kind = d & DENSIFY_KIND_MASK;
  const bool a = (d & DENSIFY_SLOT_A) != 0u;
  const bool b = (d & DENSIFY_SLOT_B) != 0u;
  const uint o = offsets[i];
  const bool zero_new = p.zero_new != 0u;
  if (a) write_row(i, o, kind == DENSIFY_KIND_SPLIT && zero_new);
  if (b) write_row(i, a ? o + 1u : o, zero_new);
}
