// The radiometric level model's shared contract (C++ and GLSL): state layout, bindings, parameters.
//
// Each frame f sees the map through x' = g_f v(p) x + o_f, with g_f = exp(lg_f) (log-gain: the gain stays
// positive) and the optional vignetting v(p) = 1 + k1 r^2 + k2 r^4 shared by all frames, r^2 the squared
// distance of pixel p's centre from the principal point over the squared half diagonal of the image.
//
// State: float [frames + 1][LEVEL_STRIDE]. Frame f's row: lg, o, Adam m(lg), m(o), v(lg), v(o), Adam steps,
// 1 if the frame is trained (else 0). The last row is the shared vignetting: k1, k2, m(k1), m(k2), v(k1),
// v(k2), Adam steps, updates skipped for a non-finite value (over every row). Identity: lg = o = k = 0.
//
// The map's own level: the gauge (g, o) -> (g / a, o - g b / a) with the map -> a map + b changes nothing
// rendered, so the step re-centres: after each update the trained frames' mean log-gain and mean offset are
// subtracted from every trained frame (their log-gains clamped first). The map then takes on the frames'
// average level, and every frame's loss, not one anchor frame's, pulls the map there.
#ifndef LITGS_KERNELS_LEVEL_SHARED_H
#define LITGS_KERNELS_LEVEL_SHARED_H

#ifdef __cplusplus
#include <cstdint>
namespace litgs::kernels {
using uint = uint32_t;
#endif

#define LEVEL_STRIDE 8
#define LEVEL_STEPS 6               // row element: Adam steps taken
#define LEVEL_TRAINED 7             // frame row element: 1 if the frame is trained (in the mean), else 0
#define LEVEL_SKIPS 7               // shared row element: updates skipped for a non-finite value
#define LEVEL_LOG_GAIN_LIMIT 1.0    // |lg| <= this: gain in [0.37, 2.7], beyond any sensor drift
#define LEVEL_VIGNETTING_LIMIT 0.5  // |k1|, |k2| <= this: v >= 0 over the image
#define LEVEL_ROWS_PER_THREAD 16
#define LEVEL_ROWS_PER_GROUP (256 * LEVEL_ROWS_PER_THREAD)

// ---- level_apply.comp: one invocation per element: out = g v x + o ----
#define LEVEL_APPLY_BINDING_IMAGE 0  // [C][H][W] x
#define LEVEL_APPLY_BINDING_STATE 1  // the state
#define LEVEL_APPLY_BINDING_OUT 2    // [C][H][W] x' (out)
#define LEVEL_APPLY_BINDING_COUNT 3

// ---- level_backward.comp: workgroup b takes elements [b R, (b + 1) R), R = LEVEL_ROWS_PER_GROUP ----
// grad_image = G g v; block sums of (G g v x, G, G g x r^2, G g x r^4) in a fixed order (no atomics).
#define LEVEL_BACKWARD_BINDING_IMAGE 0         // [C][H][W] x
#define LEVEL_BACKWARD_BINDING_GRAD_LEVELED 1  // [C][H][W] G = dL/dx'
#define LEVEL_BACKWARD_BINDING_STATE 2
#define LEVEL_BACKWARD_BINDING_GRAD_IMAGE 3  // [C][H][W] dL/dx (out, overwritten)
#define LEVEL_BACKWARD_BINDING_SUMS 4        // [blocks][4] (out)
#define LEVEL_BACKWARD_BINDING_COUNT 5

// ---- level_step.comp: one workgroup: the block sums, the regularizers, Adam on frame and vignetting ----
#define LEVEL_STEP_BINDING_SUMS 0   // [blocks][4]
#define LEVEL_STEP_BINDING_STATE 1  // the state (read and written)
#define LEVEL_STEP_BINDING_COUNT 2

// Push constants of level_apply and level_backward.
struct LevelParams {
  uint width, height;
  uint count;  // C * H * W
  uint frame;
  float cx, cy;       // principal point, pixels (pixel (i, j) has its centre at (i + 0.5, j + 0.5))
  float inv_r2_norm;  // 1 / ((W / 2)^2 + (H / 2)^2)
  uint vignetting;    // 0: v = 1
  uint frames;        // rows of frames in the state (the shared row follows them)
  uint reserved0, reserved1, reserved2;
};

// Push constants of level_step.
struct LevelStepParams {
  uint blocks;      // block sums to add
  uint frame;       // the frame whose gradient the sums are
  int prev, next;   // its neighbours in time for the smoothness term (-1: none)
  uint center;      // 1: re-centre the trained frames (the mean's gauge, above); 0: leave the other rows
  uint vignetting;  // 0: the shared row stays
  float lr_log_gain, lr_offset, lr_vignetting;
  float lambda_identity;  // adds lambda (lg^2 + o^2) per frame, lambda (k1^2 + k2^2)
  float lambda_smooth;    // adds lambda sum over neighbours ((lg - lg_n)^2 + (o - o_n)^2)
  float beta1, beta2, eps;
  uint frames;  // rows of frames in the state (the shared row follows them)
  float reserved0;
};

#ifdef __cplusplus
static_assert(sizeof(LevelParams) <= 128 && sizeof(LevelParams) % 16 == 0);
static_assert(sizeof(LevelStepParams) <= 128 && sizeof(LevelStepParams) % 16 == 0);
static_assert(LEVEL_APPLY_BINDING_COUNT == LEVEL_APPLY_BINDING_OUT + 1);
static_assert(LEVEL_BACKWARD_BINDING_COUNT == LEVEL_BACKWARD_BINDING_SUMS + 1);
static_assert(LEVEL_STEP_BINDING_COUNT == LEVEL_STEP_BINDING_STATE + 1);
}  // namespace litgs::kernels
#endif
#endif
