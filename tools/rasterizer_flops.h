// Useful floating-point work of the rasterizer, counted by hand from the shaders' arithmetic for one
// (pixel, Gaussian) pair the forward blends (SPLAT_COUNTER_CONTRIBUTIONS). Adds, subtractions,
// multiplications, divisions and negations count one each, exp() counts one (lavapipe spends about a dozen
// FMAs on it), compares and selects none. Not counted as useful: culling, loads, shuffles, and pairs a
// subgroup evaluates that contribute nothing (the lanes of a pixel the Gaussian misses).
#pragma once

#include <cstdint>

namespace litgs::tools {

// rasterize_forward.comp, per blended pair: d = centre - mean (2), sigma = 0.5 (a dx dx + c dy dy) + b dx dy
// (9), -sigma and exp (2), opacity * exp (1), T (1 - alpha) (2), w = alpha T (1), colour sum (2 per
// channel), depth sum (2).
constexpr double forward_flops_per_pair(uint32_t channels) {
  return 20.0 + 2.0 * channels;
}

// rasterize_backward.glsl entry_backward, per pair: d, sigma, exp, raw alpha (14); 1 - alpha, T / (1 -
// alpha), w (3); dL/dalpha of the image (-1 / (1 - alpha) 2, then 5 per channel less 1); of depth and alpha
// (8); dL/dsigma (2); mean and conic gradients (15); conic c, opacity, depth gradients (5); colour gradients
// (1 per channel); the colour and depth sums behind (2 per channel + 2); and one add per gradient value into
// the Gaussian's total (7 + channels).
constexpr double backward_flops_per_pair(uint32_t channels) {
  return 14.0 + 3.0 + 1.0 + 8.0 + 2.0 + 15.0 + 5.0 + 2.0 + 7.0 + 9.0 * channels;
}

}  // namespace litgs::tools
