#version 450
#extension GL_GOOGLE_include_directive : require
// Per Gaussian: 1 where it is a clone/split candidate. The exclusive scan of these is each candidate's rank.
#include "densify/densify_input.glsl"

layout(std430, binding = DECIDE_BINDING_CANDIDATE) writeonly buffer Candidate { uint candidate[]; };
layout(std430, binding = DECIDE_BINDING_RANK) readonly buffer Rank { uint rank[]; };
layout(std430, binding = DECIDE_BINDING_DECISION) writeonly buffer Decision { uint decision[]; };
layout(std430, binding = DECIDE_BINDING_COUNTS) writeonly buffer Counts { uint counts[]; };
layout(std430, binding = DECIDE_BINDING_REPORT) buffer Report { uint report[]; };

void main() {
  const uint i = elementwise_index();
  if (i >= p.count) return;
  candidate[i] = densify_candidate(p, load_input(i)) ? 1u : 0u;
}
