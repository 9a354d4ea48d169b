// The splatting kernels' shared contract (C++ and GLSL): numerics constants, bindings, parameters.
// One numerics definition is used by the forward and backward kernels and by the double-precision CPU
// reference (splat_math.h), so they cull, clamp and stop identically.
#ifndef LITGS_KERNELS_SPLAT_SHARED_H
#define LITGS_KERNELS_SPLAT_SHARED_H

#ifdef __cplusplus
#include <cstdint>
namespace litgs::kernels {
using uint = uint32_t;
#endif

// ---- Numerics ----
#define SPLAT_TILE_SIZE 16  // pixels per tile side; a forward/backward workgroup is one tile
// Pixels each rasterize invocation blends (RasterizerOptions::pixels_per_invocation; footprint.glsl
// block_origin): 8, a 2x4 block (8x4 invocations per tile: CPU devices), or 1 (16x16 invocations: GPUs).
// Specialization constants of the rasterize kernels, with the workgroup size:
#define SPLAT_SPEC_PIXEL_BLOCK 3
#define SPLAT_SPEC_GROUP_X 4
#define SPLAT_SPEC_GROUP_Y 5
#define SPLAT_BLOCK_PIXELS_MAX 8
#define SPLAT_ALPHA_MAX 0.99           // per-Gaussian alpha clamp: keeps 1 - alpha >= 0.01 for backward
#define SPLAT_ALPHA_MIN (1.0 / 255.0)  // contributions below this are skipped (and set the extent)
#define SPLAT_T_MIN 1e-4               // a pixel stops once its transmittance would fall below this
#define SPLAT_LOW_PASS 0.3             // added to the 2D covariance diagonal (pixels^2): anti-aliasing
#define SPLAT_QUAT_NORM_FLOOR 1e-8     // |q| below this: identity rotation, no rotation gradient
#define SPLAT_LOG_SCALE_MIN -30.0      // log-scales are clamped here (no gradient outside) so that
#define SPLAT_LOG_SCALE_MAX 20.0       // exp(2 s) and the projected covariance stay finite in float32
#define SPLAT_FRUSTUM_GUARD 1.3        // x/z and y/z are clamped to 1.3x the image's half-extent in J
#define SPLAT_MIN_DEPTH_WEIGHT 1e-6    // expected depth is 0 where accumulated alpha is below this
#define SPLAT_MAX_SH_COEFFS 16         // degree 3
#define SPLAT_MAX_CHANNELS 4

// Gradients per intersection in deterministic mode, and per Gaussian after the per-pixel pass:
// [mean2d.x, mean2d.y, conic.a, conic.b, conic.c, opacity, depth, color_0 .. color_{C-1}]
#define SPLAT_GRAD2D_FIXED 7

// ---- project.comp: one invocation per Gaussian ----
// The parameters (bindings 0-4) are read as texels: R32_SFLOAT, the quaternions R32G32B32A32_SFLOAT.
#define PROJECT_BINDING_MEANS 0           // [N][3] world
#define PROJECT_BINDING_LOG_SCALES 1      // [N][3]
#define PROJECT_BINDING_QUATS 2           // [N][4] w x y z, unnormalized
#define PROJECT_BINDING_OPACITY_LOGITS 3  // [N]
#define PROJECT_BINDING_SH 4              // [N][K][C] K = (max degree + 1)^2 of the model
// The projected Gaussian as two four-float records, so that the rasterize kernels read each with one texel
// fetch (engine/kernel.h TexelBinding: on CPU drivers one vector gather instead of a loop over the lanes).
#define PROJECT_BINDING_CENTRES 5  // [N][4] mean2d x, y (pixels), camera z, opacity (out)
#define PROJECT_BINDING_CONICS 6   // [N][4] inverse 2D covariance a b c, ln(max(255 opacity, 1)) (out)
#define PROJECT_BINDING_COLORS 7   // [N][C] (out)
#define PROJECT_BINDING_TILE_RECTS \
  8  // [N][2] tile x0 y0 x1 y1, half-open, 16 bits each (tile_rect.glsl); empty if culled (out)
#define PROJECT_BINDING_DEPTH_KEYS 9  // [N] sortable depth bits, 0xFFFFFFFF if culled (out)
#define PROJECT_BINDING_ORDER 10      // [N] identity permutation, the depth sort's values (out)
#define PROJECT_BINDING_COUNTERS 11   // [SPLAT_COUNTER_COUNT] uint, see SPLAT_COUNTER_*
#define PROJECT_BINDING_COUNT 12

// ---- The rasterizer's counters buffer: [SPLAT_COUNTER_COUNT] uint ----
// Zeroed by every forward: culls, the intersection total and the longest tile list of that render.
#define SPLAT_COUNTER_CULLED_NONFINITE 0  // Gaussians culled for a non-finite parameter (project.comp)
#define SPLAT_COUNTER_ISECT_LO 1          // total tile intersections, low 32 bits (gather_counts.comp)
#define SPLAT_COUNTER_ISECT_HI 2          // ... and the carries out of the low word: exact beyond 2^32
#define SPLAT_COUNTER_MAX_LIST 3          // the longest tile list (tile_list_lengths.comp)
// Never zeroed (the host reads running totals and takes differences): subgroup walks that a driver's
// loop limit ended before the end of their list segment (lavapipe ends an invocation's loops silently
// after 65535 iterations). The passes are sized so that this never happens; a non-zero value means a
// loop-cost bound below is wrong for this device.
#define SPLAT_COUNTER_FORWARD_WALKS_CUT 4
#define SPLAT_COUNTER_BACKWARD_WALKS_CUT 5
// Zeroed by every forward: the (pixel, Gaussian) pairs the forward blended (alpha >= 1/255 before the pixel
// stopped), which the backward walks again: the useful work of a render (bench render's FLOP/s). 32 bits:
// wraps beyond 2^32 pairs (a 4K image with 500 per pixel).
#define SPLAT_COUNTER_CONTRIBUTIONS 6
#define SPLAT_COUNTER_COUNT 8

// ---- gather_counts.comp: one invocation per depth-sorted position ----
#define GATHER_BINDING_ORDER 0       // [N] Gaussian index by depth rank
#define GATHER_BINDING_TILE_RECTS 1  // [N][2] packed (tile_rect.glsl)
#define GATHER_BINDING_COUNTS \
  2  // [N + 1] tiles touched, in depth order (out; scanned in place into
     // the offsets, whose element N, zeroed, becomes the total)
#define GATHER_BINDING_CORNERS \
  3                                // [(tiles_y + 1) * (tiles_x + 1)] uint, zeroed before: each
                                   // rectangle adds +1 -1 -1 +1 at its corners (a 2D difference grid)
#define GATHER_BINDING_COUNTERS 4  // SPLAT_COUNTER_ISECT_LO/HI (atomic)
#define GATHER_BINDING_COUNT 5

// ---- tile_list_lengths.comp: one workgroup; the corner grid's 2D prefix sum is each tile's list length ----
#define LENGTHS_BINDING_CORNERS 0   // [(tiles_y + 1) * (tiles_x + 1)] in: differences; out: lengths
#define LENGTHS_BINDING_COUNTERS 1  // SPLAT_COUNTER_MAX_LIST (out)
#define LENGTHS_BINDING_COUNT 2
#define LENGTHS_GROUP_SIZE 256

// ---- emit_intersections.comp: one invocation per depth-sorted position ----
#define EMIT_BINDING_ORDER 0           // [N]
#define EMIT_BINDING_TILE_RECTS 1      // [N][2] packed (tile_rect.glsl)
#define EMIT_BINDING_OFFSETS 2         // [N + 1] exclusive scan of the counts
#define EMIT_BINDING_TILE_KEYS 3       // [M] tile id (out)
#define EMIT_BINDING_ISECT_IDS 4       // [M] intersection id = its emission position (out)
#define EMIT_BINDING_ISECT_GAUSSIAN 5  // [M] Gaussian index of each intersection id (out)
#define EMIT_BINDING_COUNT 6

// ---- tile_ranges.comp: one invocation per sorted intersection ----
#define RANGES_BINDING_TILE_KEYS 0  // [M] sorted tile ids
#define RANGES_BINDING_RANGES 1     // [tiles][2] first, end (out; zero-filled before)
#define RANGES_BINDING_COUNT 2

// ---- rasterize_forward.comp: one workgroup per tile and pass ----
// A pass walks the entries [ListSegment.begin, ListSegment.end) of every tile's list. Between passes the
// per-pixel blend state rides in the output buffers: image = the colour sum so far, depth = the sum of
// w * z, alpha = the transmittance T, last = the walk length | FWD_LAST_DONE once the pixel has stopped.
// A tile's final pass (its list ends within the segment) writes the outputs proper.
#define FWD_LAST_DONE 0x80000000u
// The bindings marked (texels) are read as uniform texel buffers, in the format named.
#define FWD_BINDING_RANGES 0
#define FWD_BINDING_ISECT_IDS 1       // [M] sorted by tile, depth order within a tile (texels, R32_UINT)
#define FWD_BINDING_ISECT_GAUSSIAN 2  // [M] (texels, R32_UINT)
#define FWD_BINDING_CENTRES 3         // [N][4] (texels, R32G32B32A32_SFLOAT)
#define FWD_BINDING_CONICS 4          // [N][4] (texels, R32G32B32A32_SFLOAT)
#define FWD_BINDING_COLORS 5          // [N][C] (texels, R32_SFLOAT)
#define FWD_BINDING_IMAGE 6           // [C][H][W] (out)
#define FWD_BINDING_DEPTH 7           // [H][W] expected depth sum(w z)/sum(w) (out)
#define FWD_BINDING_ALPHA 8           // [H][W] accumulated alpha = 1 - T (out)
#define FWD_BINDING_LAST 9            // [H][W] number of list entries the pixel walked (out)
#define FWD_BINDING_COUNTERS 10       // SPLAT_COUNTER_FORWARD_WALKS_CUT (atomic)
#define FWD_BINDING_COUNT 11

// ---- rasterize_backward.comp: one workgroup per tile and pass ----
// Passes run from the last list segment to the first. A pixel's running state (transmittance, the colour
// and depth sums of what lies behind) is stored in BWD_BINDING_STATE by the pass that walks past it and
// loaded by the next; a pixel whose walk ends before a pass's segment starts from the forward's results.
#define BWD_BINDING_RANGES 0
#define BWD_BINDING_ISECT_IDS 1       // (texels, R32_UINT)
#define BWD_BINDING_ISECT_GAUSSIAN 2  // (texels, R32_UINT)
#define BWD_BINDING_CENTRES 3         // (texels, R32G32B32A32_SFLOAT)
#define BWD_BINDING_CONICS 4          // (texels, R32G32B32A32_SFLOAT)
#define BWD_BINDING_COLORS 5          // (texels, R32_SFLOAT)
#define BWD_BINDING_DEPTH 6           // forward expected depth
#define BWD_BINDING_ALPHA 7           // forward accumulated alpha
#define BWD_BINDING_LAST 8
#define BWD_BINDING_GRAD_IMAGE 9   // [C][H][W]
#define BWD_BINDING_GRAD_DEPTH 10  // [H][W]
#define BWD_BINDING_GRAD_ALPHA 11  // [H][W]
#define BWD_BINDING_GRAD2D 12      // atomic mode: [N][7 + C] float; deterministic: [M][7 + C]
#define BWD_BINDING_STATE 13       // [2 + C][H][W]: T, depth sum, colour sums (single pass: unused)
#define BWD_BINDING_COUNTERS 14    // SPLAT_COUNTER_BACKWARD_WALKS_CUT (atomic)
#define BWD_BINDING_COUNT 15

// ---- reduce_isect_grads.comp (deterministic mode): one invocation per depth-sorted position ----
#define REDUCE_BINDING_ORDER 0
#define REDUCE_BINDING_OFFSETS 1      // [N + 1]: position s owns intersections offsets[s] .. offsets[s + 1]
#define REDUCE_BINDING_ISECT_GRADS 2  // [M][7 + C]
#define REDUCE_BINDING_GRAD2D 3       // [N][7 + C] (out)
#define REDUCE_BINDING_COUNT 4

// ---- project_backward.comp: one invocation per Gaussian ----
// The parameters (bindings 0-4) and the gradient rows are read as texels: R32_SFLOAT, the quaternions
// R32G32B32A32_SFLOAT.
#define PBWD_BINDING_MEANS 0
#define PBWD_BINDING_LOG_SCALES 1
#define PBWD_BINDING_QUATS 2
#define PBWD_BINDING_OPACITY_LOGITS 3
#define PBWD_BINDING_SH 4
#define PBWD_BINDING_TILE_RECTS 5            // culled Gaussians get zero gradients
#define PBWD_BINDING_GRAD2D 6                // [N][7 + C]
#define PBWD_BINDING_GRAD_MEANS 7            // [N][3] (out)
#define PBWD_BINDING_GRAD_LOG_SCALES 8       // [N][3] (out)
#define PBWD_BINDING_GRAD_QUATS 9            // [N][4] (out)
#define PBWD_BINDING_GRAD_OPACITY_LOGITS 10  // [N] (out)
#define PBWD_BINDING_GRAD_SH 11              // [N][K][C] (out)
#define PBWD_BINDING_COUNT 12

// The view: world-to-camera pose, pinhole intrinsics, image size. Push constants of every splat kernel.
struct SplatView {
  float rot[9];          // R_cam_world, column-major
  float trans[3];        // t_cam_world: p_cam = R p_world + t
  float fx, fy, cx, cy;  // pixels; pixel (i, j) has its centre at (i + 0.5, j + 0.5)
  float near_m;          // Gaussians nearer than this (camera z) are culled
  uint width, height;    // pixels
  uint tiles_x, tiles_y;
  uint count;      // Gaussians (or intersections / sorted positions, per kernel)
  uint sh_degree;  // active degree 0..3 (<= the model's)
  uint sh_coeffs;  // K of the model's SH buffer (1, 4, 9 or 16)
};

// The list segment of one rasterize pass, in entries counted from each tile's list start: [begin, end).
struct ListSegment {
  uint begin;
  uint end;
};

// Push constants of rasterize_forward and rasterize_backward.
struct RasterizeParams {
  SplatView view;
  ListSegment segment;
};

#ifdef __cplusplus
static_assert(sizeof(SplatView) <= 128);
static_assert(sizeof(RasterizeParams) <= 128);
static_assert(sizeof(SplatView) % 4 == 0, "the segment follows the view at a 4-byte boundary, as std430");
static_assert(PROJECT_BINDING_COUNT == PROJECT_BINDING_COUNTERS + 1);
static_assert(GATHER_BINDING_COUNT == GATHER_BINDING_COUNTERS + 1);
static_assert(LENGTHS_BINDING_COUNT == LENGTHS_BINDING_COUNTERS + 1);
static_assert(EMIT_BINDING_COUNT == EMIT_BINDING_ISECT_GAUSSIAN + 1);
static_assert(RANGES_BINDING_COUNT == RANGES_BINDING_RANGES + 1);
static_assert(FWD_BINDING_COUNT == FWD_BINDING_COUNTERS + 1);
static_assert(BWD_BINDING_COUNT == BWD_BINDING_COUNTERS + 1);
static_assert(REDUCE_BINDING_COUNT == REDUCE_BINDING_GRAD2D + 1);
static_assert(PBWD_BINDING_COUNT == PBWD_BINDING_GRAD_SH + 1);
}  // namespace litgs::kernels
#endif
#endif
