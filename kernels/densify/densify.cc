#include "kernels/densify/densify.h"

#include <cmath>
#include <stdexcept>

namespace litgs::kernels {

namespace {

void require(bool ok, const char* field, double value, const char* rule) {
  if (!ok)
    throw std::invalid_argument(std::string("DensifyOptions.") + field + " = " + std::to_string(value) +
                                ": " + rule);
}

}  // namespace

void DensifyOptions::check() const {
  require(grad_threshold >= 0 && std::isfinite(grad_threshold), "grad_threshold", grad_threshold,
          "must be finite and >= 0");
  require(percent_dense > 0 && std::isfinite(percent_dense), "percent_dense", percent_dense, "must be > 0");
  require(split_scale_divisor > 1 && std::isfinite(split_scale_divisor), "split_scale_divisor",
          split_scale_divisor, "must be > 1");
  require(min_opacity > 0 && min_opacity < 1, "min_opacity", min_opacity, "must be in (0, 1)");
  require(max_world_scale > 0, "max_world_scale", max_world_scale, "must be > 0");
  require(max_screen_radius_px > 0, "max_screen_radius_px", max_screen_radius_px, "must be > 0");
  require(!std::isnan(max_plane_distance_m) && max_plane_distance_m >= 0, "max_plane_distance_m",
          max_plane_distance_m, "must be >= 0 (infinity: off)");
  require(reset_opacity > 0 && reset_opacity < 1, "reset_opacity", reset_opacity, "must be in (0, 1)");
}

std::string DensifyReport::to_string() const {
  return std::to_string(before) + " -> " + std::to_string(after) + " Gaussians: " + std::to_string(cloned) +
         " cloned, " + std::to_string(split) + " split, " + std::to_string(capped) + " capped; pruned " +
         std::to_string(pruned_nonfinite) + " non-finite, " + std::to_string(pruned_opacity) +
         " transparent, " + std::to_string(pruned_plane) + " off-plane, " +
         std::to_string(pruned_world_size) + " large, " + std::to_string(pruned_screen_size) +
         " large on screen";
}

DensifyParams make_densify_params(const DensifyOptions& o, float scene_extent, uint32_t step, uint32_t count,
                                  uint32_t sh_values, bool plane_prune) {
  o.check();
  if (!(scene_extent > 0) || !std::isfinite(scene_extent))
    throw std::invalid_argument("densify: scene_extent = " + std::to_string(scene_extent) + " must be > 0");
  DensifyParams p{};
  p.count = count;
  p.sh_values = sh_values;
  p.budget = o.max_gaussians == 0 ? 0xFFFFFFFFu : (o.max_gaussians > count ? o.max_gaussians - count : 0u);
  p.flags = (step > o.opacity_reset_interval ? DENSIFY_FLAG_SIZE_PRUNE : 0u) |
            (plane_prune && std::isfinite(o.max_plane_distance_m) ? DENSIFY_FLAG_PLANE_PRUNE : 0u);
  p.grad_threshold = o.grad_threshold;
  p.log_clone_max_scale = static_cast<float>(std::log(double{o.percent_dense} * scene_extent));
  p.log_world_max_scale = static_cast<float>(std::log(double{o.max_world_scale} * scene_extent));
  p.max_screen_radius = o.max_screen_radius_px;
  p.min_opacity_logit = static_cast<float>(std::log(double{o.min_opacity} / (1.0 - o.min_opacity)));
  p.max_plane_distance = o.max_plane_distance_m;
  p.log_split_divisor = static_cast<float>(std::log(double{o.split_scale_divisor}));
  p.seed = o.seed;
  p.step = step;
  return p;
}

}  // namespace litgs::kernels
