// Adaptive density control on the device (3DGS semantics): bindings, parameters and the report layout
// shared by C++ and GLSL. The kernels:
//   densify_stats      per Gaussian, every training step: accumulate the screen-space mean gradient norm,
//                      the visibility count and the maximum screen radius of visible Gaussians.
//   densify_candidates per Gaussian: 1 where the Gaussian is a clone/split candidate (then scanned: ranks).
//   densify_decide     per Gaussian: what becomes of it (keep, clone, split, prune; see densify_math.h) and
//                      how many rows it writes (0, 1 or 2), report counters.
//   densify_scatter_rows / densify_scatter_geometry
//                      per Gaussian: write its rows at the exclusive scan of those counts (stream
//                      compaction).
//   densify_reset_opacity  per Gaussian: logit = min(logit, max_logit).
#ifndef LITGS_KERNELS_DENSIFY_SHARED_H
#define LITGS_KERNELS_DENSIFY_SHARED_H

#ifdef __cplusplus
#include <cstdint>
namespace litgs::kernels {
using uint = uint32_t;
#endif

// ---- densify_stats.comp (push constants: SplatView of the rendered camera, count = N) ----
#define STATS_BINDING_MEANS 0           // [N][3]   (the screen radius is recomputed with project_gaussian)
#define STATS_BINDING_LOG_SCALES 1      // [N][3]
#define STATS_BINDING_QUATS 2           // [N][4]
#define STATS_BINDING_OPACITY_LOGITS 3  // [N]
#define STATS_BINDING_TILE_RECTS 4  // [N][2] uint, the rasterizer's, packed; empty (x1 <= x0): not visible
#define STATS_BINDING_GRAD2D 5      // [N][SPLAT_GRAD2D_FIXED + C] the rasterizer's; dL/d(pixel) in 0, 1
#define STATS_BINDING_GRAD_ACCUM 6  // [N] float += |(dL/du W/2, dL/dv H/2)| where visible
#define STATS_BINDING_DENOM 7       // [N] uint += 1 where visible
#define STATS_BINDING_MAX_RADIUS 8  // [N] float = max(., max(extent.x, extent.y)) pixels where visible
#define STATS_BINDING_COUNT 9

// ---- densify_candidates.comp and densify_decide.comp (push constants: DensifyParams) ----
#define DECIDE_BINDING_MEANS 0           // [N][3]
#define DECIDE_BINDING_LOG_SCALES 1      // [N][3]
#define DECIDE_BINDING_QUATS 2           // [N][4]
#define DECIDE_BINDING_OPACITY_LOGITS 3  // [N]
#define DECIDE_BINDING_SH 4              // [N][sh_values]
#define DECIDE_BINDING_GRAD_ACCUM 5      // [N]
#define DECIDE_BINDING_DENOM 6           // [N] uint
#define DECIDE_BINDING_MAX_RADIUS 7      // [N]
#define DECIDE_BINDING_PLANE_DISTANCE 8  // [N] metres, used when flags & DENSIFY_FLAG_PLANE_PRUNE
#define DECIDE_BINDING_CANDIDATE 9       // [N] uint 0/1: candidates writes it
#define DECIDE_BINDING_RANK 10           // [N] uint exclusive scan of CANDIDATE: decide reads it
#define DECIDE_BINDING_DECISION 11       // [N] uint DENSIFY_KIND_* | DENSIFY_SLOT_A | DENSIFY_SLOT_B (decide)
#define DECIDE_BINDING_COUNTS 12         // [N] uint rows written: 0, 1 or 2 (decide)
#define DECIDE_BINDING_REPORT 13         // [DENSIFY_REPORT_SLOTS] uint (decide, atomic)
#define DECIDE_BINDING_COUNT 14

// Decision word.
#define DENSIFY_KIND_MASK 3u
#define DENSIFY_KIND_KEEP 0u   // slot A: the Gaussian itself
#define DENSIFY_KIND_CLONE 1u  // slot A: the Gaussian itself; slot B: an exact copy (new)
#define DENSIFY_KIND_SPLIT 2u  // slots A and B: two children sampled from the Gaussian (both new)
#define DENSIFY_SLOT_A 4u      // slot A is written
#define DENSIFY_SLOT_B 8u      // slot B is written (at offset + 1 if slot A is written, else at offset)

// Flags of DensifyParams.flags.
#define DENSIFY_FLAG_SIZE_PRUNE 1u   // prune by world and screen size (3DGS: after the first opacity reset)
#define DENSIFY_FLAG_PLANE_PRUNE 2u  // prune where plane_distance > max_plane_distance

// Report counters (one download per densify call, with the new count).
#define DENSIFY_REPORT_CLONED 0            // clone operations
#define DENSIFY_REPORT_SPLIT 1             // split operations (parent replaced by two children)
#define DENSIFY_REPORT_CAPPED 2            // candidates left alone because of max_gaussians
#define DENSIFY_REPORT_PRUNED_NONFINITE 3  // rows dropped, by the first reason that applies, in this order
#define DENSIFY_REPORT_PRUNED_OPACITY 4
#define DENSIFY_REPORT_PRUNED_PLANE 5
#define DENSIFY_REPORT_PRUNED_WORLD_SIZE 6
#define DENSIFY_REPORT_PRUNED_SCREEN_SIZE 7
#define DENSIFY_REPORT_LAST_OFFSET 8  // copied: scan[N-1]
#define DENSIFY_REPORT_LAST_COUNT 9   // copied: counts[N-1]; new N = the sum of the two
#define DENSIFY_REPORT_SLOTS 12

// Prune reasons (0: kept), in priority order; reason r counts at DENSIFY_REPORT_PRUNED_NONFINITE + r - 1.
#define PRUNE_NONE 0u
#define PRUNE_NONFINITE 1u
#define PRUNE_OPACITY 2u
#define PRUNE_PLANE 3u
#define PRUNE_WORLD_SIZE 4u
#define PRUNE_SCREEN_SIZE 5u

struct DensifyParams {
  uint count;                 // N
  uint sh_values;             // K * C per Gaussian
  uint budget;                // candidates with rank < budget are densified (each adds at most one row)
  uint flags;                 // DENSIFY_FLAG_*
  float grad_threshold;       // candidate: grad_accum >= grad_threshold * denom (and denom > 0)
  float log_clone_max_scale;  // clone when max log-scale <= this (log(percent_dense * extent)), else split
  float log_world_max_scale;  // size prune: max log-scale > this (log(0.1 * extent))
  float max_screen_radius;    // size prune: max_radius > this (pixels)
  float min_opacity_logit;    // prune: logit < this (logit(0.005))
  float max_plane_distance;   // plane prune: distance > this (metres); NaN distances never prune
  float log_split_divisor;    // children's log-scales = parent's - this (log(1.6))
  uint seed;                  // split sampling: hash(seed, step, index, child, axis)
  uint step;
  uint reserved0, reserved1, reserved2;
};

// ---- densify_scatter_rows.comp (push constants: ScatterParams): one attribute buffer ----
#define SCATTER_BINDING_DECISION 0  // [N]
#define SCATTER_BINDING_OFFSETS 1   // [N] exclusive scan of counts
#define SCATTER_BINDING_SRC 2       // [N][stride] 32-bit words
#define SCATTER_BINDING_DST 3       // [new N][stride]
#define SCATTER_BINDING_COUNT 4

// ---- densify_scatter_geometry.comp (push constants: ScatterParams): means and log-scales ----
#define GEOMETRY_BINDING_DECISION 0
#define GEOMETRY_BINDING_OFFSETS 1
#define GEOMETRY_BINDING_MEANS 2           // [N][3]
#define GEOMETRY_BINDING_LOG_SCALES 3      // [N][3]
#define GEOMETRY_BINDING_QUATS 4           // [N][4]
#define GEOMETRY_BINDING_MEANS_OUT 5       // [new N][3]
#define GEOMETRY_BINDING_LOG_SCALES_OUT 6  // [new N][3]
#define GEOMETRY_BINDING_COUNT 7

struct ScatterParams {
  uint count;     // N
  uint stride;    // words per row (rows kernel)
  uint zero_new;  // rows kernel: 1 writes zeros to new rows (clone copies, split children), 0 copies
  uint seed;      // geometry kernel: as DensifyParams
  uint step;
  float log_split_divisor;
  uint reserved0, reserved1;
};

// ---- densify_reset_opacity.comp (push constants: ResetOpacityParams) ----
#define RESET_BINDING_OPACITY_LOGITS 0  // [N] updated in place
#define RESET_BINDING_COUNT 1

struct ResetOpacityParams {
  uint count;
  float max_logit;  // logit = min(logit, max_logit); NaN stays NaN (and is pruned later)
  uint reserved0, reserved1;
};

#ifdef __cplusplus
static_assert(sizeof(DensifyParams) <= 128);
static_assert(sizeof(ScatterParams) <= 128);
static_assert(sizeof(ResetOpacityParams) <= 128);
static_assert(STATS_BINDING_COUNT == STATS_BINDING_MAX_RADIUS + 1);
static_assert(DECIDE_BINDING_COUNT == DECIDE_BINDING_REPORT + 1);
static_assert(SCATTER_BINDING_COUNT == SCATTER_BINDING_DST + 1);
static_assert(GEOMETRY_BINDING_COUNT == GEOMETRY_BINDING_LOG_SCALES_OUT + 1);
static_assert(RESET_BINDING_COUNT == RESET_BINDING_OPACITY_LOGITS + 1);
}  // namespace litgs::kernels
#endif
#endif
