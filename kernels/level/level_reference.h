// Double-precision CPU reference of the level model's kernels (level_shared.h, level_model.h): the apply,
// the backward (image gradient and the parameters' gradient sums), and the optimizer step with its
// regularizers, on a state held in doubles.
#pragma once

#include <array>
#include <cstdint>
#include <vector>

#include "kernels/level/level_model.h"

namespace litgs::kernels {

// r^2 of element e over the squared half diagonal, as level_pixel.glsl.
double level_r2_reference(const LevelGeometry& geometry, uint64_t element);

// x' = g v x + o.
std::vector<double> level_apply_reference(const std::vector<float>& image, const LevelGeometry& geometry,
                                          const LevelValues& values, bool vignetting);

struct LevelBackwardReference {
  std::vector<double> grad_image;  // dL/dx = G g v
  // dL/d(log-gain), dL/d(offset), dL/dk1, dL/dk2 (the data term only; the regularizers are the step's).
  std::array<double, 4> grad{};
};
LevelBackwardReference level_backward_reference(const std::vector<float>& image,
                                                const std::vector<float>& grad_leveled,
                                                const LevelGeometry& geometry, const LevelValues& values,
                                                bool vignetting);

// The regularizers' value: lambda_identity (lg^2 + o^2 of every frame, + k1^2 + k2^2 with vignetting) +
// lambda_smooth sum over neighbouring pairs ((lg_a - lg_b)^2 + (o_a - o_b)^2); `pairs` lists each pair once.
double level_regularizer_reference(const std::vector<double>& state, uint32_t frames, bool vignetting,
                                   double lambda_identity, double lambda_smooth,
                                   const std::vector<std::array<uint32_t, 2>>& pairs);

// The gradient level_step.comp descends: `grad` (the data term) plus the regularizers' gradient of
// step.frame's log-gain and offset ([0], [1]; the pairs (frame, prev) and (frame, next)) and of the
// vignetting ([2], [3]).
std::array<double, 4> level_step_gradient_reference(const std::vector<double>& state, uint32_t frames,
                                                    const std::array<double, 4>& grad, const LevelStep& step);

// One step as level_step.comp: `grad` from the backward, the regularizers' gradient of step.frame's row
// (and of the vignetting), Adam, the clamps (a non-finite update leaves its row and counts a skip), then with
// step.center the trained frames re-centred on their mean (level_shared.h).
void level_step_reference(std::vector<double>& state, uint32_t frames, bool vignetting,
                          const std::array<double, 4>& grad, const LevelStep& step);

}  // namespace litgs::kernels
