// The loss kernels' shared contract (C++ and GLSL): SSIM constants, bindings, parameters.
//
// Layouts: images are [C][H][W] float (the rasterizer's layout), element e = (c * H + y) * W + x; depth is
// [H][W]; LiDAR maps are [H][W][4]. Every kernel here is element-wise, ELEMENTWISE_GROUP_SIZE wide, and
// uses no subgroup operations (so it runs with any subgroup size).
#ifndef LITGS_KERNELS_LOSS_SHARED_H
#define LITGS_KERNELS_LOSS_SHARED_H

#ifdef __cplusplus
#include <cstdint>
namespace litgs::kernels {
using uint = uint32_t;
#endif

// ---- SSIM (as 3DGS's ssim(): 11x11 Gaussian window, sigma 1.5, zero padding, per channel) ----
#define SSIM_RADIUS 5
#define SSIM_SIGMA 1.5
#define SSIM_C1 (0.01 * 0.01)
#define SSIM_C2 (0.03 * 0.03)
// The normalized 1D window, w_k = exp(-k^2 / (2 sigma^2)) / sum_j exp(-j^2 / (2 sigma^2)), k = -5..5
// (a CPU test checks these literals against the formula). The 2D window is the outer product.
#define SSIM_W0 0.266011725
#define SSIM_W1 0.213005538
#define SSIM_W2 0.109360690
#define SSIM_W3 0.0360007721
#define SSIM_W4 0.00759875814
#define SSIM_W5 0.00102838008

// The SSIM kernels read their inputs (every binding not marked "out") as uniform texel buffers, R32_SFLOAT
// for the [C][H][W] maps and R32G32B32A32_SFLOAT for the [C][H][W][4] ones
// (kernels/loss/photometric_loss.cc).

// ---- ssim_moments_h.comp: one invocation per element, horizontal blur of the five moment maps ----
#define SSIM_MOMENTS_BINDING_IMAGE 0   // [C][H][W] x
#define SSIM_MOMENTS_BINDING_TARGET 1  // [C][H][W] y
#define SSIM_MOMENTS_BINDING_OUT4 2    // [C][H][W][4] row sums G*x, G*y, G*x^2, G*y^2 (out)
#define SSIM_MOMENTS_BINDING_OUT1 3    // [C][H][W] row sums G*xy (out)
#define SSIM_MOMENTS_BINDING_COUNT 4

// ---- ssim_pixel.comp: one invocation per element: vertical blur, SSIM, its partials, the L1 term ----
#define SSIM_PIXEL_BINDING_IMAGE 0     // [C][H][W] x
#define SSIM_PIXEL_BINDING_TARGET 1    // [C][H][W] y
#define SSIM_PIXEL_BINDING_MOMENTS4 2  // [C][H][W][4] from ssim_moments_h
#define SSIM_PIXEL_BINDING_MOMENTS1 3  // [C][H][W] from ssim_moments_h
#define SSIM_PIXEL_BINDING_PARTIALS 4  // [C][H][W][4] dL/d(mu_x), dL/d(E[x^2]), dL/d(E[xy]), 0 (out)
#define SSIM_PIXEL_BINDING_TERMS 5     // [C][H][W][2] (1 - SSIM, |x - y|) (out)
#define SSIM_PIXEL_BINDING_COUNT 6

// ---- ssim_partials_h.comp: one invocation per element, horizontal blur of the three partial maps ----
#define SSIM_PARTIALS_BINDING_IN 0   // [C][H][W][4]
#define SSIM_PARTIALS_BINDING_OUT 1  // [C][H][W][4] (out)
#define SSIM_PARTIALS_BINDING_COUNT 2

// ---- ssim_backward.comp: one invocation per element: vertical blur of the partials, combine ----
#define SSIM_BACKWARD_BINDING_IMAGE 0     // [C][H][W] x
#define SSIM_BACKWARD_BINDING_TARGET 1    // [C][H][W] y
#define SSIM_BACKWARD_BINDING_PARTIALS 2  // [C][H][W][4] from ssim_partials_h
#define SSIM_BACKWARD_BINDING_GRAD 3      // [C][H][W] weight * dL_pho/dx (out, overwritten)
#define SSIM_BACKWARD_BINDING_COUNT 4

// Push constants of the four photometric kernels.
struct PhotometricParams {
  uint width, height;
  uint count;  // C * H * W
  uint reserved;
  float lambda_ssim;  // L = (1 - lambda) mean|x - y| + lambda (1 - mean SSIM)
  float inv_count;    // 1 / (C * H * W)
  float weight;       // the gradient is weight * dL/dx
  float reserved2;
};

// ---- geometric.comp: one invocation per pixel: point-to-plane residual and dL/dD ----
#define GEOMETRIC_BINDING_DEPTH 0  // [H][W] rendered expected depth, metres (0: nothing rendered)
// [H][W][4] the pixel's LiDAR plane target (n_x, n_y, n_z, n . P): unit normal and the point's offset along
// it (camera frame, metres); n = 0 where the pixel has no LiDAR point (GeometricLoss::pack_plane_targets)
#define GEOMETRIC_BINDING_PLANES 1
#define GEOMETRIC_BINDING_GRAD 2   // [H][W] weight * dL_geo/dD, metres^-1 * m^2 (out, overwritten)
#define GEOMETRIC_BINDING_TERMS 3  // [H][W][2] (rho(r), 1 if the pixel counted else 0) (out)
#define GEOMETRIC_BINDING_COUNT 4

struct GeometricParams {
  uint width, height;
  uint count;  // H * W
  uint reserved;
  float fx, fy, cx, cy;  // pixels; pixel (u, v) has its centre at (u + 0.5, v + 0.5)
  float inv_valid;       // 1 / N_valid, 0 when there are no valid points
  float weight;          // the gradient is weight * dL/dD
  float inv_scale2;      // 1 / s^2 of the Cauchy kernel, metres^-2; 0: the plain square (geometric_loss.h)
  float reserved3;
};

// ---- reduce_blocks.comp / reduce_finish.comp: deterministic sums of vec2 rows ----
// reduce_blocks: workgroup b sums rows [b * R, (b + 1) * R), R = LOSS_REDUCE_ROWS_PER_GROUP; thread t takes
// rows t, t + 256, ... in order, then a fixed shared-memory tree. reduce_finish: one workgroup sums the
// block sums the same way and writes up to three outputs. No atomics: the same input gives the same bits.
#define LOSS_REDUCE_ROWS_PER_THREAD 16
#define LOSS_REDUCE_ROWS_PER_GROUP (256 * LOSS_REDUCE_ROWS_PER_THREAD)
#define REDUCE_BLOCKS_BINDING_ROWS 0  // [count][2]
#define REDUCE_BLOCKS_BINDING_SUMS 1  // [blocks][2] (out)
#define REDUCE_BLOCKS_BINDING_COUNT 2
#define REDUCE_FINISH_BINDING_SUMS 0  // [blocks][2]
#define REDUCE_FINISH_BINDING_OUT 1   // float loss buffer: [slot .. slot + outputs) written
#define REDUCE_FINISH_BINDING_COUNT 2

// With (s0, s1) the sums of the two columns, output j (j < outputs) is
//   out[slot + j] = bias_j + w_j0 * s0 + w_j1 * s1.
struct ReduceParams {
  uint count;    // rows (blocks: input rows; finish: block sums)
  uint slot;     // first output element of the loss buffer
  uint outputs;  // 1..3
  uint reserved;
  float bias0, w00, w01, reserved0;
  float bias1, w10, w11, reserved1;
  float bias2, w20, w21, reserved2;
};

#ifdef __cplusplus
static_assert(sizeof(PhotometricParams) <= 128 && sizeof(PhotometricParams) % 16 == 0);
static_assert(sizeof(GeometricParams) <= 128 && sizeof(GeometricParams) % 16 == 0);
static_assert(sizeof(ReduceParams) <= 128 && sizeof(ReduceParams) % 16 == 0);
static_assert(SSIM_MOMENTS_BINDING_COUNT == SSIM_MOMENTS_BINDING_OUT1 + 1);
static_assert(SSIM_PIXEL_BINDING_COUNT == SSIM_PIXEL_BINDING_TERMS + 1);
static_assert(SSIM_PARTIALS_BINDING_COUNT == SSIM_PARTIALS_BINDING_OUT + 1);
static_assert(SSIM_BACKWARD_BINDING_COUNT == SSIM_BACKWARD_BINDING_GRAD + 1);
static_assert(GEOMETRIC_BINDING_COUNT == GEOMETRIC_BINDING_TERMS + 1);
static_assert(REDUCE_BLOCKS_BINDING_COUNT == REDUCE_BLOCKS_BINDING_SUMS + 1);
static_assert(REDUCE_FINISH_BINDING_COUNT == REDUCE_FINISH_BINDING_OUT + 1);
}  // namespace litgs::kernels
#endif
#endif
