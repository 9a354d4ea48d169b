// The Gaussian budget a scene needs, derived from what the training views see (`train --max-gaussians
// auto`): the observed surface, measured in pixels of the finest training view that sees each part of it,
// divided by the pixels one Gaussian is given. A fixed budget the user must guess is replaced by one that
// grows with the surface and the training resolution.
//
// The surface comes from points on it (the LiDAR map, or the initialization's points): each point stands
// for the area pi r_k^2 / k around it, r_k the distance to its k-th nearest neighbour (a density estimate:
// right for evenly or randomly spread points, within ~5% on a square grid at k = 16), so sparse SfM points
// account for the surface between them. Each point's area is converted to pixels at the finest footprint
// (depth / focal length) among the training views whose image it projects into. Occlusion is not checked:
// a point hidden from its nearest view is counted at that view's finer footprint, so the figure is an upper
// estimate of the pixels the views resolve.
#pragma once

#include <Eigen/Core>
#include <cstdint>
#include <string>
#include <vector>

#include "kernels/splat/splat_types.h"

namespace litgs::host {

struct SceneBudgetOptions {
  // Pixels of surface per Gaussian: 4, a 2x2 block, since the smallest Gaussian the rasterizer resolves
  // (its screen-space dilation of 0.3 px^2, sigma ~0.55 px) spans about two pixels.
  double pixels_per_gaussian = 4.0;
  uint32_t neighbours = 16;  // k of the area estimate
  // Isolated points (stray triangulations) would claim the empty space around them: r_k is clamped at
  // median + outlier_mads * 1.4826 MAD of all points' r_k.
  double outlier_mads = 5.0;
  uint32_t min_gaussians = 1000;     // a floor for tiny or nearly unseen scenes
  uint32_t max_gaussians = 4000000;  // the MCMC strategy's row limit (MCMC_MAX_GAUSSIANS)
  void check() const;                // throws std::invalid_argument naming the bad field
};

struct SceneBudget {
  uint32_t gaussians = 0;         // the budget
  size_t points = 0;              // points given
  size_t points_seen = 0;         // of them inside at least one training view
  double surface_m2 = 0;          // area the seen points stand for
  double surface_pixels = 0;      // that area in pixels of its finest training view
  double median_footprint_m = 0;  // median over seen points of the finest pixel footprint
};

// The budget for `points` (scene frame) seen by `cameras` (the training views at the training resolution).
// std::invalid_argument when no point is in any view (nothing to derive a budget from) or a camera is
// invalid; non-finite points are skipped.
SceneBudget derive_scene_budget(const std::vector<Eigen::Vector3d>& points,
                                const std::vector<kernels::SplatCamera>& cameras,
                                const SceneBudgetOptions& options = {});

// For each point: 1 when it is finite and projects into at least one of `cameras` (in front of its near
// plane), else 0. The points derive_scene_budget counts as seen; the LiDAR-map initialization keeps only
// these, since a Gaussian no training view sees is never trained.
std::vector<uint8_t> inside_any_view(const std::vector<Eigen::Vector3d>& points,
                                     const std::vector<kernels::SplatCamera>& cameras);

}  // namespace litgs::host
