// Adaptive density control (3DGS densify_and_prune and reset_opacity): options, report, and the kernel
// parameters built from them. The device work lives in TrainableGaussians (kernels/optim/); the CPU
// reference in densify_reference.h.
#pragma once

#include <cstdint>
#include <limits>
#include <string>

#include "kernels/densify/densify_shared.h"

namespace litgs::kernels {

struct DensifyOptions {
  // Clone/split where the mean screen-gradient norm over the views that saw the Gaussian is at least this.
  // The norm is 3DGS's: of (dL/du * W/2, dL/dv * H/2), the gradient w.r.t. NDC, so 3DGS's threshold holds
  // for a loss that is a mean over pixels (3DGS densify_grad_threshold).
  float grad_threshold = 2e-4f;
  // Clone when the largest scale is at most percent_dense x extent, else split (3DGS percent_dense).
  float percent_dense = 0.01f;
  // Split children: scales / this (3DGS: 0.8 x 2 children).
  float split_scale_divisor = 1.6f;
  // Prune where opacity < this (3DGS min_opacity in densify_and_prune).
  float min_opacity = 0.005f;
  // After the first opacity reset (step > opacity_reset_interval), also prune where the largest scale
  // > max_world_scale x extent or the largest screen radius seen since the last densification
  // > max_screen_radius_px (3DGS: 0.1 x extent and 20 px).
  float max_world_scale = 0.1f;
  float max_screen_radius_px = 20.0f;
  uint32_t opacity_reset_interval = 3000;  // 3DGS opacity_reset_interval
  // Prune where the caller's per-Gaussian plane distance exceeds this (metres); needs the distance buffer.
  // NaN distances (no plane) never prune. Infinity: off.
  float max_plane_distance_m = std::numeric_limits<float>::infinity();
  // Total Gaussians after densification at most this (0: no cap). When the candidates would exceed it, the
  // first max_gaussians - N candidates in index order are densified (deterministic; a densification adds at
  // most one row, and rows pruned in the same call do not make room for it; they do for the next call).
  uint32_t max_gaussians = 0;
  // Split sampling seed: children depend only on (seed, step, index).
  uint32_t seed = 0;
  // 3DGS zeroes the statistics of every Gaussian after densifying; false keeps the survivors' statistics
  // (new Gaussians start from zero either way).
  bool reset_stats = true;
  // Opacity reset (3DGS reset_opacity): opacity = min(opacity, this).
  float reset_opacity = 0.01f;

  // Throws std::invalid_argument naming the bad field.
  void check() const;
};

struct DensifyReport {
  uint32_t before = 0;            // Gaussians in
  uint32_t cloned = 0;            // clone operations (+1 row each)
  uint32_t split = 0;             // split operations (a parent replaced by 2 children: +1 row each)
  uint32_t capped = 0;            // candidates not densified because of max_gaussians
  uint32_t pruned_nonfinite = 0;  // rows dropped, counted by the first reason in this order
  uint32_t pruned_opacity = 0;
  uint32_t pruned_plane = 0;
  uint32_t pruned_world_size = 0;
  uint32_t pruned_screen_size = 0;
  uint32_t after = 0;  // Gaussians out = before + cloned + split - pruned()

  uint32_t pruned() const {
    return pruned_nonfinite + pruned_opacity + pruned_plane + pruned_world_size + pruned_screen_size;
  }
  std::string to_string() const;
};

// The kernels' parameters for a model of `count` Gaussians with `sh_values` SH values each.
DensifyParams make_densify_params(const DensifyOptions& options, float scene_extent, uint32_t step,
                                  uint32_t count, uint32_t sh_values, bool plane_prune);

}  // namespace litgs::kernels
