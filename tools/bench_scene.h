// The seeded random scene of `bench render`: documented so that figures stay comparable.
#pragma once

#include <cstdint>

#include "kernels/splat/splat_types.h"

namespace litgs::tools {

// N Gaussians filling the view of a camera at the origin looking down +z (horizontal field of view 60
// degrees, square pixels):
// - depth z uniform in [2, 10] m, x and y uniform over the image at that depth;
// - log-scales: a per-Gaussian base size so that the mean footprint radius is sqrt(8 W H / (pi N)) pixels
//   (the image is covered about 8 times over at any N, like a trained scene's many small Gaussians,
//   clamped to 0.5 .. 64 px), times a per-axis factor log-uniform in [1/2, 2]; random rotations;
// - opacity logit uniform in [-1, 3] (opacity 0.27 .. 0.95);
// - SH: DC uniform in [-1, 1], higher coefficients uniform in [-0.1, 0.1].
kernels::GaussianModel bench_scene(uint32_t n, uint32_t channels, uint32_t sh_degree, uint32_t width,
                                   uint32_t height, uint32_t seed);
kernels::SplatCamera bench_camera(uint32_t width, uint32_t height, uint32_t sh_degree);

}  // namespace litgs::tools
