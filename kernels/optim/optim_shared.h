// Adam on the device: bindings and parameters shared by C++ and GLSL (kernels/optim/adam.comp).
// One element-wise dispatch per parameter buffer; the learning rate and the bias corrections of the step
// come in push constants, so one kernel serves every parameter group.
#ifndef LITGS_KERNELS_OPTIM_SHARED_H
#define LITGS_KERNELS_OPTIM_SHARED_H

#ifdef __cplusplus
#include <cstdint>
namespace litgs::kernels {
using uint = uint32_t;
#endif

// ---- adam.comp: one invocation per parameter element (kernels/elementwise.h) ----
#define ADAM_BINDING_PARAMS 0      // [count] float, updated in place
#define ADAM_BINDING_GRADS 1       // [count] float dL/dparam
#define ADAM_BINDING_EXP_AVG 2     // [count] float first moment m, updated in place
#define ADAM_BINDING_EXP_AVG_SQ 3  // [count] float second moment v, updated in place
#define ADAM_BINDING_COUNTERS 4    // [ADAM_COUNTER_SLOTS] uint: [counter_slot] += elements skipped (atomic)
#define ADAM_BINDING_COUNT 5

// One counter per parameter group: elements whose gradient (or whose updated value) was not finite. Such an
// element keeps its parameter and both moments.
#define ADAM_COUNTER_SLOTS 8

struct AdamParams {
  uint count;         // elements in the buffer
  uint period;        // element j uses lr when (j % period) < lead, else lr_rest (SH: period K*C, lead C)
  uint lead;          //   period = lead = 1 for a group with one learning rate
  uint counter_slot;  // < ADAM_COUNTER_SLOTS
  float lr;
  float lr_rest;
  float beta1;
  float beta2;
  float eps;
  float bias_correction1;       // 1 - beta1^step (step counted from 1)
  float sqrt_bias_correction2;  // sqrt(1 - beta2^step)
  uint reserved;
};

// ---- gaussian_adam.comp: the projection's backward, 3DGS-MCMC's regularizers and Adam for every parameter
// group in one pass, one invocation per Gaussian: each gradient computed from the rasterizer's per-Gaussian
// rows (splat/param_gradients.glsl) and applied at once, so that training stores no parameter gradient
// (44 B + the SH's per Gaussian). Counter slot g counts group g's skipped elements (ParamGroup order:
// means, log_scales, quats, opacity_logits, sh). ----
#define GAUSSIAN_ADAM_BINDING_MEANS 0           // [N][3] float, updated in place
#define GAUSSIAN_ADAM_BINDING_LOG_SCALES 1      // [N][3]
#define GAUSSIAN_ADAM_BINDING_QUATS 2           // [N][4]
#define GAUSSIAN_ADAM_BINDING_OPACITY_LOGITS 3  // [N]
#define GAUSSIAN_ADAM_BINDING_SH 4              // [N][K][C]
#define GAUSSIAN_ADAM_BINDING_EXP_AVG 5         // five bindings from here: the groups' first moments
#define GAUSSIAN_ADAM_BINDING_EXP_AVG_SQ 10     // five bindings from here: the groups' second moments
#define GAUSSIAN_ADAM_BINDING_COUNTERS 15       // [ADAM_COUNTER_SLOTS] uint
#define GAUSSIAN_ADAM_BINDING_TILE_RECTS 16     // [N][2] packed: an empty rectangle means culled, no gradient
#define GAUSSIAN_ADAM_BINDING_GRAD2D 17         // [N][SPLAT_GRAD2D_FIXED + C] float, the backward's rows
#define GAUSSIAN_ADAM_BINDING_COUNT 18
#define GAUSSIAN_ADAM_GROUPS 5

// Push constants: the view (as SplatView, without the tile grid) and the step. beta1, beta2 and eps are
// specialization constants (2, 3, 4), so that all of it fits the 128 bytes every device offers.
struct GaussianAdamParams {
  float rot[9];          // R_cam_world, column-major
  float trans[3];        // t_cam_world
  float fx, fy, cx, cy;  // pixels
  float near_m;
  uint width, height;
  uint count;                      // Gaussians
  uint sh_degree;                  // active degree
  uint sh_coeffs;                  // K of the SH buffer
  float lr[GAUSSIAN_ADAM_GROUPS];  // means, log_scales, quats, opacity_logits, SH degree 0
  float lr_sh_rest;                // the SH coefficients above degree 0
  float bias_correction1;          // 1 - beta1^step (step counted from 1)
  float sqrt_bias_correction2;     // sqrt(1 - beta2^step)
  float opacity_reg;               // added to each opacity logit's gradient: opacity_reg * o (1 - o)
  float scale_reg;                 // added to each log-scale's gradient: scale_reg * exp(log_scale)
};

#ifdef __cplusplus
static_assert(sizeof(AdamParams) <= 128);
static_assert(sizeof(GaussianAdamParams) <= 128);
static_assert(GAUSSIAN_ADAM_BINDING_COUNT == GAUSSIAN_ADAM_BINDING_GRAD2D + 1);
static_assert(GAUSSIAN_ADAM_GROUPS <= ADAM_COUNTER_SLOTS);
static_assert(ADAM_BINDING_COUNT == ADAM_BINDING_COUNTERS + 1);
}  // namespace litgs::kernels
#endif
#endif
