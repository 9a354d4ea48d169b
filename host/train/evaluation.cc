#include "host/train/evaluation.h"

#include <algorithm>
#include <cmath>

#include "kernels/loss/loss_reference.h"

namespace litgs::host {

PlaneResidualSum depth_plane_residuals(const PlanarMap& truth_map, const kernels::SplatCamera& cam,
                                       std::span<const float> depth, std::span<const float> alpha) {
  // Point-to-plane residual of the rendered depth along each pixel's ray, where a true plane is seen and the
  // render is opaque enough to have a depth.
  const ViewPlaneMaps truth = project_planes(truth_map, cam);
  PlaneResidualSum sum;
  const uint32_t W = cam.width, H = cam.height;
  for (uint32_t y = 0; y < H; ++y)
    for (uint32_t x = 0; x < W; ++x) {
      const size_t p = size_t{y} * W + x;
      if (truth.points[4 * p + 3] != 1.0f || alpha[p] < 0.5f) continue;
      const double rx = (x + 0.5 - cam.cx) / cam.fx, ry = (y + 0.5 - cam.cy) / cam.fy, D = depth[p];
      const double r = truth.normals[4 * p] * (truth.points[4 * p] - D * rx) +
                       truth.normals[4 * p + 1] * (truth.points[4 * p + 1] - D * ry) +
                       truth.normals[4 * p + 2] * (truth.points[4 * p + 2] - D);
      sum.sum_sq_m2 += r * r;
      ++sum.count;
    }
  return sum;
}

Evaluator::Evaluator(const TrainingData& data, const TrainOptions& o, const PlanarMap* gt_planes,
                     kernels::Rasterizer& rasterizer)
    : data_(&data), options_(&o), gt_planes_(gt_planes), rasterizer_(&rasterizer) {
  for (uint32_t i = 0; i < data.views.size(); ++i)
    if (data.views[i].heldout) views_.push_back(i);
}

namespace {
double mean_abs_diff(const std::vector<float>& a, const std::vector<float>& b) {
  double s = 0;
  for (size_t i = 0; i < a.size(); ++i) s += std::abs(static_cast<double>(a[i]) - b[i]);
  return a.empty() ? 0.0 : s / static_cast<double>(a.size());
}
}  // namespace

std::vector<float> shown_as_written(std::span<const float> render) {
  std::vector<float> shown(render.begin(), render.end());
  for (float& v : shown) v = std::clamp(v, 0.0f, 1.0f);
  return shown;
}

EvalResult Evaluator::evaluate(const kernels::DeviceGaussians& gaussians, uint32_t iteration,
                               std::vector<kernels::RenderImages<float>>* renders, const LevelTable* levels) {
  if (renders) renders->clear();
  const uint32_t W = data_->width, H = data_->height;
  EvalResult e;
  e.iteration = iteration;
  if (views_.empty()) return e;
  e.mae_counts = 0;
  e.leveled = levels != nullptr;
  if (levels) e.mae_counts_identity = 0;
  double plane_sq = 0;
  size_t plane_n = 0;
  for (uint32_t i : views_) {
    kernels::SplatCamera cam = data_->views[i].camera;
    cam.sh_degree = options_->active_sh_degree(iteration);
    rasterizer_->forward(gaussians, cam);
    const auto img = rasterizer_->download_images();
    const std::vector<float>& target = data_->views[i].image;
    const double counts = data_->stretch_high - data_->stretch_low;
    if (levels) {
      const kernels::LevelGeometry g{W, H, 1, static_cast<float>(cam.cx), static_cast<float>(cam.cy)};
      const std::vector<float> leveled =
          shown_as_written(apply_level(img.image, g, levels->values(i), levels->vignetting()));
      const std::vector<float> identity = shown_as_written(img.image);
      e.view_psnr_db.emplace_back(data_->views[i].name, kernels::psnr(leveled, target));
      e.psnr_db += e.view_psnr_db.back().second;
      e.ssim += kernels::ssim_reference(leveled, target, 1, W, H);
      e.mae_counts += counts * mean_abs_diff(leveled, target);
      e.psnr_identity_db += kernels::psnr(identity, target);
      e.mae_counts_identity += counts * mean_abs_diff(identity, target);
    } else {
      const std::vector<float> shown = shown_as_written(img.image);
      e.view_psnr_db.emplace_back(data_->views[i].name, kernels::psnr(shown, target));
      e.psnr_db += e.view_psnr_db.back().second;
      e.ssim += kernels::ssim_reference(shown, target, 1, W, H);
      e.mae_counts += counts * mean_abs_diff(shown, target);
    }
    if (gt_planes_) {
      const PlaneResidualSum r = depth_plane_residuals(*gt_planes_, cam, img.depth, img.alpha);
      plane_sq += r.sum_sq_m2;
      plane_n += r.count;
    }
    if (renders) renders->push_back(img);
  }
  const double n = static_cast<double>(views_.size());
  e.psnr_db /= n;
  e.ssim /= n;
  e.mae_counts /= n;
  e.psnr_identity_db /= n;
  if (levels) e.mae_counts_identity /= n;
  if (gt_planes_ && plane_n > 0) e.depth_plane_rmse_m = std::sqrt(plane_sq / static_cast<double>(plane_n));
  return e;
}

}  // namespace litgs::host
