// Double-precision CPU references of the training losses (the same math as the kernels in this folder,
// evaluated in double: for tests, and for host-side evaluation: ssim_reference, psnr). Images are
// [C][H][W]; see photometric_loss.h and geometric_loss.h for the definitions and conventions.
#pragma once

#include <cstdint>
#include <span>
#include <vector>

namespace litgs::kernels {

// The normalized 11-tap SSIM window, w[k + 5] for k = -5..5, in double from its formula.
std::vector<double> ssim_window();

struct PhotometricLossResult {
  double loss = 0.0;  // (1 - lambda) mean_l1 + lambda (1 - mean_ssim)
  double mean_ssim = 0.0;
  double mean_l1 = 0.0;
  std::vector<double> grad;  // [C][H][W] dloss/dimage (unweighted); empty unless asked for
};

// Throws std::invalid_argument when the spans do not hold C*H*W values or lambda is outside [0, 1].
PhotometricLossResult photometric_loss_reference(std::span<const double> image,
                                                 std::span<const double> target, uint32_t channels,
                                                 uint32_t width, uint32_t height, double lambda_ssim = 0.2,
                                                 bool gradient = true);

struct GeometricLossResult {
  double loss = 0.0;               // metres^2 (mean of rho(r))
  uint32_t counted = 0;            // pixels with a valid point and a rendered depth
  std::vector<double> grad_depth;  // [H][W] dloss/dD (unweighted)
};

// depth [H][W], points and normals [H][W][4]; valid_count = N_valid (0: loss 0, gradient 0); robust_scale_m
// the Cauchy kernel's s (0: squares), as geometric_loss.h.
GeometricLossResult geometric_loss_reference(std::span<const double> depth, std::span<const float> points,
                                             std::span<const float> normals, uint32_t width, uint32_t height,
                                             double fx, double fy, double cx, double cy, uint32_t valid_count,
                                             double robust_scale_m = 0.0);

// Mean SSIM over all pixels and channels (3DGS's ssim(), as the photometric loss), in double.
double ssim_reference(std::span<const float> image, std::span<const float> target, uint32_t channels,
                      uint32_t width, uint32_t height);

// PSNR in dB of image against target, 10 log10(data_range^2 / MSE) over all values; +infinity when equal.
double psnr(std::span<const float> image, std::span<const float> target, double data_range = 1.0);

}  // namespace litgs::kernels
