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

// ---- sh_adam.comp: Adam on the SH coefficients, their gradient computed in the kernel from the colour
// gradient of the rasterizer's per-Gaussian rows (no stored SH gradient). One invocation per Gaussian. ----
#define SH_ADAM_BINDING_SH 0          // [N][K][C] float, updated in place
#define SH_ADAM_BINDING_EXP_AVG 1     // [N][K][C] float, updated in place
#define SH_ADAM_BINDING_EXP_AVG_SQ 2  // [N][K][C] float, updated in place
#define SH_ADAM_BINDING_COUNTERS 3    // [ADAM_COUNTER_SLOTS] uint
#define SH_ADAM_BINDING_MEANS 4       // [N][3] float: the means the backward used (before their own step)
#define SH_ADAM_BINDING_TILE_RECTS 5  // [N][2] packed tile rectangles: an empty one means culled, no gradient
#define SH_ADAM_BINDING_GRAD2D 6      // [N][SPLAT_GRAD2D_FIXED + C] float: the colour gradient at the end
#define SH_ADAM_BINDING_COUNT 7

struct ShAdamParams {
  AdamParams adam;  // count: Gaussians; period K * C and lead C as for the SH buffer in adam.comp
  float centre[3];  // camera centre in world coordinates
  uint sh_degree;   // active degree (basis beyond it is 0)
  uint sh_coeffs;   // K of the SH buffer
  uint reserved;
};

#ifdef __cplusplus
static_assert(sizeof(AdamParams) <= 128);
static_assert(sizeof(ShAdamParams) <= 128);
static_assert(SH_ADAM_BINDING_COUNT == SH_ADAM_BINDING_GRAD2D + 1);
static_assert(ADAM_BINDING_COUNT == ADAM_BINDING_COUNTERS + 1);
}  // namespace litgs::kernels
#endif
#endif
