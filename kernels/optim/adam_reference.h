// torch.optim.Adam's step in double, element by element: the reference of kernels/optim/adam.comp.
#pragma once

#include <cmath>
#include <cstdint>

#include "kernels/optim/adam.h"

namespace litgs::kernels {

// One step (counted from 1). Returns false, changing nothing, when the gradient or a result is not finite.
inline bool adam_reference_step(double& param, double& exp_avg, double& exp_avg_sq, double grad, double lr,
                                const AdamOptions& o, uint32_t step) {
  const double b1 = o.beta1, b2 = o.beta2;
  const double m = b1 * exp_avg + (1.0 - b1) * grad;
  const double v = b2 * exp_avg_sq + (1.0 - b2) * grad * grad;
  const double bc1 = 1.0 - std::pow(b1, step), bc2 = 1.0 - std::pow(b2, step);
  const double x = param - (lr / bc1) * m / (std::sqrt(v) / std::sqrt(bc2) + double{o.eps});
  if (!std::isfinite(grad) || !std::isfinite(m) || !std::isfinite(v) || !std::isfinite(x)) return false;
  param = x;
  exp_avg = m;
  exp_avg_sq = v;
  return true;
}

}  // namespace litgs::kernels
