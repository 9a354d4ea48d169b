#version 450
#extension GL_GOOGLE_include_directive : require
// Per Gaussian: the decision (densify_math.h), the rows it writes, and the report counters. Candidates of
// rank < budget are densified (the first in index order: deterministic, and the cap holds exactly).
#include "densify/densify_input.glsl"

layout(std430, binding = DECIDE_BINDING_CANDIDATE) readonly buffer Candidate { uint candidate[]; };
layout(std430, binding = DECIDE_BINDING_RANK) readonly buffer Rank { uint rank[]; };
layout(std430, binding = DECIDE_BINDING_DECISION) writeonly buffer Decision { uint decision[]; };
layout(std430, binding = DECIDE_BINDING_COUNTS) writeonly buffer Counts { uint counts[]; };
layout(std430, binding = DECIDE_BINDING_REPORT) buffer Report { uint report[]; };

void main() {
  const uint i = elementwise_index();
  if (i >= p.count) return;
  const DensifyInput g = load_input(i);
  const bool is_candidate = candidate[i] != 0u;
  const bool within_budget = rank[i] < p.budget;
  uint reason_a, reason_b;
  const uint d = densify_decision(p, g, within_budget, reason_a, reason_b);
  decision[i] = d;
  counts[i] = ((d & DENSIFY_SLOT_A) != 0u ? 1u : 0u) + ((d & DENSIFY_SLOT_B) != 0u ? 1u : 0u);
  const uint kind = d & DENSIFY_KIND_MASK;
  if (kind == DENSIFY_KIND_CLONE) atomicAdd(report[DENSIFY_REPORT_CLONED], 1u);
  if (kind == DENSIFY_KIND_SPLIT) atomicAdd(report[DENSIFY_REPORT_SPLIT], 1u);
  if (is_candidate && !within_budget) atomicAdd(report[DENSIFY_REPORT_CAPPED], 1u);
  if (reason_a != PRUNE_NONE) atomicAdd(report[DENSIFY_REPORT_PRUNED_NONFINITE + reason_a - 1u], 1u);
  if (kind != DENSIFY_KIND_KEEP && reason_b != PRUNE_NONE)
    atomicAdd(report[DENSIFY_REPORT_PRUNED_NONFINITE + reason_b - 1u], 1u);
}
