// The double-precision CPU reference of the rasterizer: the same math as the kernels (splat_math.h), the
// same culling, tiling, depth order and stopping rule, evaluated in double. Slow; for tests and --reference.
#pragma once

#include "kernels/splat/splat_types.h"

namespace litgs::kernels {

RenderImages<double> reference_forward(const GaussianModel& model, const SplatCamera& camera);

// Gradients of sum(grad_out . outputs) w.r.t. the model's parameters. depth_gradient_to_opacity = false:
// the depth and alpha gradients skip the opacity (RasterizerOptions::depth_gradient_to_opacity).
GaussianGrads<double> reference_backward(const GaussianModel& model, const SplatCamera& camera,
                                         const RenderGradInput& grad_out,
                                         bool depth_gradient_to_opacity = true);

}  // namespace litgs::kernels
