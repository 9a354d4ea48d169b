#include "host/train/trainer.h"

#include <chrono>
#include <cmath>
#include <limits>
#include <memory>
#include <stdexcept>

#include "engine/buffer.h"
#include "host/train/checkpoint.h"
#include "host/train/evaluation.h"
#include "host/train/metrics_json.h"
#include "host/train/refinement.h"
#include "host/train/training_step.h"
#include "host/train/view_sampler.h"
#include "io/gaussian_ply.h"
#include "kernels/mcmc/mcmc.h"
#include "kernels/optim/trainable_gaussians.h"
#include "kernels/splat/rasterizer.h"

namespace litgs::host {

namespace fs = std::filesystem;

void TrainOptions::check() const {
  auto bad = [](const std::string& what) { throw std::invalid_argument("TrainOptions." + what); };
  if (iterations == 0) bad("iterations must be positive");
  if (!(lambda_geo >= 0 && lambda_geo <= 1)) bad("lambda_geo must be in [0, 1]");
  if (!(lambda_ssim >= 0 && lambda_ssim <= 1)) bad("lambda_ssim must be in [0, 1]");
  if (!(geo_robust_scale_m >= 0) || !std::isfinite(geo_robust_scale_m))
    bad("geo_robust_scale_m must be finite and >= 0 (0: squared residuals)");
  if (sh_degree > 3) bad("sh_degree must be 0..3");
  if (!(plane_prune_k >= 0) || !std::isfinite(plane_prune_k))
    bad("plane_prune_k must be >= 0 (0: no plane prune)");
  if (sh_degree_every == 0) bad("sh_degree_every must be positive");
  if (densify_every == 0) bad("densify_every must be positive");
  if (opacity_reset_every == 0) bad("opacity_reset_every must be positive");
  if (!(densify_grad_threshold > 0)) bad("densify_grad_threshold must be positive");
  if (max_gaussians == 0) bad("max_gaussians must be positive");
  if (!(lr_scale > 0) || !std::isfinite(lr_scale)) bad("lr_scale must be positive");
  if (strategy != "adc" && strategy != "mcmc") bad("strategy must be adc or mcmc, not '" + strategy + "'");
  if (strategy == "mcmc") mcmc_options().check();
}

kernels::McmcOptions TrainOptions::mcmc_options() const {
  kernels::McmcOptions m;
  m.max_gaussians = max_gaussians;
  m.growth = mcmc_growth;
  m.noise_lr = mcmc_noise_lr;
  m.opacity_reg = static_cast<float>(mcmc_opacity_reg * photometric_weight());
  m.scale_reg = static_cast<float>(mcmc_scale_reg * photometric_weight());
  m.seed = seed;
  return m;
}

TrainReport train(engine::Context& ctx, const TrainingData& data, const kernels::GaussianModel& initial,
                  const PlanarMap* planes, const TrainOptions& o, const fs::path& out_dir,
                  const std::function<void(const TrainProgress&)>& progress, const PlanarMap* gt_planes) {
  o.check();
  if (o.lambda_geo > 0 && !planes)
    throw std::invalid_argument("lambda_geo > 0 needs a LiDAR map (the scene has none); use --lambda-geo 0");
  std::vector<uint32_t> train_views;
  for (uint32_t i = 0; i < data.views.size(); ++i)
    if (!data.views[i].heldout) train_views.push_back(i);
  if (train_views.empty()) throw std::invalid_argument("no training views (all held out)");
  fs::create_directories(out_dir);
  if (o.checkpoint_every > 0) fs::create_directories(out_dir / "checkpoints");

  // Device state: the rasterizer is shared by the training step and the evaluation.
  kernels::RasterizerOptions ropt;
  ropt.deterministic = o.deterministic;
  ropt.depth_gradient_to_opacity = o.geo_gradient_to_opacity;
  kernels::Rasterizer rasterizer(ctx, 1, ropt);
  TrainingStep training_step(ctx, data, planes, o, rasterizer);
  Evaluator evaluator(data, o, gt_planes, rasterizer);

  // The model, fresh or from the newest checkpoint.
  std::unique_ptr<kernels::TrainableGaussians> model;
  ViewSampler sampler(train_views, o.seed);
  uint32_t start = 0;
  if (o.resume) {
    const fs::path ckpt = newest_checkpoint(out_dir);
    if (ckpt.empty())
      throw std::invalid_argument("--resume: no checkpoint in " + (out_dir / "checkpoints").string());
    const Checkpoint c = read_checkpoint(ckpt);
    model = std::make_unique<kernels::TrainableGaussians>(ctx, c.state);
    try {
      sampler.restore(c);
    } catch (const std::invalid_argument& e) {
      throw std::invalid_argument(ckpt.string() + ": " + e.what());
    }
    start = c.iteration;
  } else {
    model = std::make_unique<kernels::TrainableGaussians>(ctx, initial);
  }
  std::unique_ptr<kernels::McmcStrategy> mcmc;
  if (o.strategy == "mcmc") mcmc = std::make_unique<kernels::McmcStrategy>(ctx);
  Refinement refinement(ctx, o, planes, static_cast<float>(data.scene_extent_m));

  TrainReport report;
  TrainingCounters counters;
  double last_psnr = std::numeric_limits<double>::quiet_NaN();
  KernelTimes kernel_ms;
  const auto t0 = std::chrono::steady_clock::now();
  for (uint32_t it = start; it < o.iterations; ++it) {
    const uint32_t step = it + 1;
    training_step.run(*model, mcmc.get(), it, sampler.next(), kernel_ms);
    refinement.after_step(*model, mcmc.get(), step, counters);
    const bool last = step == o.iterations;
    if (o.eval_every > 0 && (step % o.eval_every == 0) && !last) {
      report.evals.push_back(evaluator.evaluate(model->gaussians(), step));
      last_psnr = report.evals.back().psnr_db;
    }
    if (o.checkpoint_every > 0 && step % o.checkpoint_every == 0) {
      Checkpoint c;
      c.iteration = step;
      sampler.save(c);
      c.state = model->download_state();
      write_checkpoint(checkpoint_path(out_dir, step), c);
    }
    if (progress && (step % o.progress_every == 0 || last || step == start + 1)) {
      const StepLosses l = training_step.last_losses();
      const double secs = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
      progress({step, o.iterations, l.total, l.photometric, l.geometric_rms_m, last_psnr, model->size(),
                (step - start) / std::max(secs, 1e-9)});
    }
  }
  const double wall = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  const double done_iterations = std::max(1.0, static_cast<double>(o.iterations - start));
  for (const auto& [name, ms] : kernel_ms)
    report.kernel_ms_per_iteration.emplace_back(name, ms / done_iterations);
  report.final_eval = evaluator.evaluate(model->gaussians(), o.iterations);
  report.evals.push_back(report.final_eval);
  report.iterations = o.iterations;
  report.wall_s = wall;
  report.ms_per_iteration = o.iterations > start ? 1000.0 * wall / (o.iterations - start) : 0.0;
  report.gaussians = model->size();
  report.peak_device_bytes = engine::Buffer::peak_bytes();
  report.nonfinite_pruned = counters.pruned_nonfinite;
  report.plane_pruned = counters.pruned_plane;

  io::write_gaussian_ply(out_dir / "point_cloud.ply", model->download());
  write_metrics_json(out_dir / "metrics.json", report, data, o);
  return report;
}

}  // namespace litgs::host
