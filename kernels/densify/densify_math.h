// The decisions of adaptive density control and the split sampler, written once in the common subset of
// GLSL and C++: the kernels and the CPU reference (densify_reference.cc) decide identically, bit for bit
// (float comparisons of the same float values; the thresholds come precomputed in DensifyParams).
#ifndef LITGS_KERNELS_DENSIFY_MATH_H
#define LITGS_KERNELS_DENSIFY_MATH_H

#ifdef __cplusplus
#include <cstdint>

#include "kernels/densify/densify_shared.h"
namespace litgs::kernels::densify_math {
using uint = uint32_t;
#define DM_FN inline
#define DM_OUT(T) T&
#else
#define DM_FN
#define DM_OUT(T) out T
#endif

// What densification looks at, per Gaussian.
struct DensifyInput {
  bool finite;          // every parameter finite (means, log-scales, quaternion, opacity logit, SH)
  float max_log_scale;  // max of the three log-scales
  float opacity_logit;
  float grad_accum;      // sum of screen-gradient norms (DENSIFY stats)
  uint denom;            // times visible
  float max_radius;      // pixels
  float plane_distance;  // metres (NaN: no plane)
};

// Rows kept, or the reason for dropping them, before any densification.
DM_FN uint base_prune_reason(DensifyParams p, DensifyInput g) {
  if (!g.finite) return PRUNE_NONFINITE;
  if (g.opacity_logit < p.min_opacity_logit) return PRUNE_OPACITY;
  if ((p.flags & DENSIFY_FLAG_PLANE_PRUNE) != 0u && g.plane_distance > p.max_plane_distance)
    return PRUNE_PLANE;
  return PRUNE_NONE;
}

// 3DGS: grads = accum / denom; densify where |grads| >= threshold (compared without the division).
DM_FN bool densify_candidate(DensifyParams p, DensifyInput g) {
  return base_prune_reason(p, g) == PRUNE_NONE && g.denom > 0u &&
         g.grad_accum >= p.grad_threshold * float(g.denom);
}

// The decision word (DENSIFY_KIND_* | DENSIFY_SLOT_*) and the prune reason of each unwritten slot.
// 3DGS order: densify first (clones and split children are new, with zero screen radius), then prune
// everything by opacity and, after the first opacity reset, by world size and screen radius. So: a kept
// or cloned original can be pruned by its world size or screen radius; a clone copy only by world size
// (its radius is zero); split children by their own world size (the parent's / divisor).
DM_FN uint densify_decision(DensifyParams p, DensifyInput g, bool within_budget, DM_OUT(uint) reason_a,
                            DM_OUT(uint) reason_b) {
  reason_b = PRUNE_NONE;
  const bool sized = (p.flags & DENSIFY_FLAG_SIZE_PRUNE) != 0u;
  const bool world_big = sized && g.max_log_scale > p.log_world_max_scale;
  const bool screen_big = sized && g.max_radius > p.max_screen_radius;
  const uint base = base_prune_reason(p, g);
  uint own = base;
  if (own == PRUNE_NONE && world_big) own = PRUNE_WORLD_SIZE;
  if (own == PRUNE_NONE && screen_big) own = PRUNE_SCREEN_SIZE;
  if (!densify_candidate(p, g) || !within_budget) {
    reason_a = own;
    return DENSIFY_KIND_KEEP | (own == PRUNE_NONE ? DENSIFY_SLOT_A : 0u);
  }
  if (g.max_log_scale <= p.log_clone_max_scale) {
    reason_a = own;
    reason_b = world_big ? PRUNE_WORLD_SIZE : PRUNE_NONE;
    return DENSIFY_KIND_CLONE | (reason_a == PRUNE_NONE ? DENSIFY_SLOT_A : 0u) |
           (reason_b == PRUNE_NONE ? DENSIFY_SLOT_B : 0u);
  }
  const bool child_big = sized && (g.max_log_scale - p.log_split_divisor) > p.log_world_max_scale;
  reason_a = child_big ? PRUNE_WORLD_SIZE : PRUNE_NONE;
  reason_b = reason_a;
  return DENSIFY_KIND_SPLIT | (child_big ? 0u : (DENSIFY_SLOT_A | DENSIFY_SLOT_B));
}

// ---- Split sampler: a counter-based hash, so a child's sample depends only on (seed, step, index) ----

// PCG-RXS-M-XS 32 (Jarzynski and Olano, "Hash Functions for GPU Rendering", 2020).
DM_FN uint pcg_hash(uint x) {
  const uint state = x * 747796405u + 2891336453u;
  const uint word = ((state >> ((state >> 28u) + 4u)) ^ state) * 277803737u;
  return (word >> 22u) ^ word;
}

// A uniform in (0, 1), exact in float: (23-bit integer + 0.5) / 2^23.
DM_FN float split_uniform(uint seed, uint step, uint index, uint child, uint axis, uint which) {
  const uint h =
      pcg_hash(pcg_hash(pcg_hash(pcg_hash(seed) ^ step) ^ index) ^ (child * 8u + axis * 2u + which));
  return (float(h >> 9u) + 0.5f) * (1.0f / 8388608.0f);
}

#ifdef __cplusplus
}  // namespace litgs::kernels::densify_math
#endif
#undef DM_FN
#undef DM_OUT
#endif
