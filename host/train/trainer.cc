#include "host/train/trainer.h"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <iostream>
#include <limits>
#include <memory>
#include <optional>
#include <stdexcept>
#include <utility>

#include "engine/buffer.h"
#include "host/train/budget_growth.h"
#include "host/train/checkpoint.h"
#include "host/train/density_control.h"
#include "host/train/evaluation.h"
#include "host/train/level_plan.h"
#include "host/train/metrics_json.h"
#include "host/train/output_frame.h"
#include "host/train/run_options.h"
#include "host/train/shrink_model.h"
#include "host/train/training_step.h"
#include "host/train/view_sampler.h"
#include "io/gaussian_ply.h"
#include "kernels/level/level_model.h"
#include "kernels/mcmc/mcmc.h"
#include "kernels/optim/trainable_gaussians.h"
#include "kernels/splat/rasterizer.h"

namespace litgs::host {

namespace fs = std::filesystem;

namespace {

// Where a run starts: a fresh model, or the newest checkpoint in the output directory (the model, the view
// sampler's state, and the run record: evaluations, counters, resumes).
struct RunStart {
  std::unique_ptr<kernels::TrainableGaussians> model;
  uint32_t iteration = 0;
  RunRecord record;
  std::vector<float> level_state;  // the checkpoint's (empty: identity, or no level model)
};

// The model on the device; only ADC reads the densification statistics, so MCMC does not keep them.
std::unique_ptr<kernels::TrainableGaussians> trainable_model(engine::Context& ctx,
                                                             const kernels::TrainingState& state,
                                                             const TrainOptions& o) {
  return std::make_unique<kernels::TrainableGaussians>(ctx, state, kernels::AdamOptions{},
                                                       o.strategy == "adc");
}

// `before_restore` sees the checkpoint's run record before the sampler's state is restored (the growth's
// state decides which views the sampler visits).
RunStart start_run(engine::Context& ctx, const kernels::GaussianModel& initial, const TrainOptions& o,
                   const fs::path& out_dir, const nlohmann::json& options, ViewSampler& sampler,
                   const std::function<void(const std::string&)>& notice,
                   const std::function<void(const RunRecord&)>& before_restore) {
  RunStart s;
  if (!o.resume) {
    s.model = trainable_model(ctx, kernels::TrainingState::fresh(initial), o);
    s.record.options = options;
    return s;
  }
  const fs::path ckpt = newest_checkpoint(out_dir);
  if (ckpt.empty())
    throw std::invalid_argument("--resume: no checkpoint in " + (out_dir / "checkpoints").string());
  Checkpoint c = read_checkpoint(ckpt);
  if (c.has_record) {
    for (const std::string& note : check_resume_options(ckpt, c.iteration, c.record.options, options))
      notice("resume: " + note);
  } else {
    notice("resume: warning: " + ckpt.string() +
           " predates stored options (checkpoint format 1): they cannot be compared, so make sure this run's "
           "are "
           "the checkpoint's; its evaluations and counters before iteration " +
           std::to_string(c.iteration) + " are unknown, and metrics.json counts from there");
  }
  if (c.iteration > o.iterations)
    throw std::invalid_argument(ckpt.string() + ": the checkpoint is at iteration " +
                                std::to_string(c.iteration) + ", beyond --iterations " +
                                std::to_string(o.iterations));
  before_restore(c.record);
  try {
    sampler.restore(c);
  } catch (const std::invalid_argument& e) {
    throw std::invalid_argument(ckpt.string() + ": " + e.what());
  }
  notice("resume: from " + ckpt.string() + " (iteration " + std::to_string(c.iteration) + " of " +
         std::to_string(o.iterations) + ")");
  s.model = trainable_model(ctx, c.state, o);
  s.iteration = c.iteration;
  s.level_state = std::move(c.level_state);
  s.record = std::move(c.record);
  s.record.options = options;  // later checkpoints store this run's options (an extended --iterations)
  s.record.resumes.push_back({c.iteration, c.has_record});
  return s;
}

void save_checkpoint(const fs::path& out_dir, uint32_t step, const ViewSampler& sampler,
                     const kernels::TrainableGaussians& model, const kernels::LevelModel* level,
                     const RunRecord& record) {
  Checkpoint c;
  c.iteration = step;
  sampler.save(c);
  c.state = model.download_state();
  if (level) c.level_state = level->download_state();
  c.record = record;
  write_checkpoint(checkpoint_path(out_dir, step), c);
}

// point_cloud.ply in the original world frame (the scene's means + world_offset_m), or with recentred_output
// in the scene's; its header states which (output_frame.h).
void write_model(const fs::path& path, const kernels::TrainableGaussians& model, const TrainingData& data,
                 const TrainOptions& o) {
  ModelFrame frame;
  frame.scene_world_offset_m = data.world_offset_m;
  frame.world_offset_m = o.recentred_output ? data.world_offset_m : Eigen::Vector3d::Zero();
  kernels::GaussianModel m = model.download();
  if (!o.recentred_output) m = shift_means(std::move(m), data.world_offset_m);
  io::write_gaussian_ply(path, m, model_frame_comments(frame));
}

// The training views' indices; throws std::invalid_argument when the inputs cannot be trained.
std::vector<uint32_t> check_inputs(const TrainingData& data, const PlanarMap* planes, const TrainOptions& o) {
  o.check();
  if (o.lambda_geo > 0 && !planes)
    throw std::invalid_argument("lambda_geo > 0 needs a LiDAR map (the scene has none); use --lambda-geo 0");
  std::vector<uint32_t> train_views;
  for (uint32_t i = 0; i < data.views.size(); ++i)
    if (!data.views[i].heldout) train_views.push_back(i);
  if (train_views.empty()) throw std::invalid_argument("no training views (all held out)");
  return train_views;
}

// Adds an evaluation; the final one replaces one the checkpoint may already hold for the same iteration.
void add_evaluation(RunRecord& record, const EvalResult& e) {
  if (!record.evaluations.empty() && record.evaluations.back().iteration == e.iteration)
    record.evaluations.back() = e;
  else
    record.evaluations.push_back(e);
}

// The report of a call that ran iterations start..iterations in `wall_s` (GPU times `kernel_ms`).
TrainReport make_report(const RunRecord& record, const kernels::TrainableGaussians& model,
                        const TrainOptions& o, uint32_t start, double wall_s, const KernelTimes& kernel_ms) {
  TrainReport report;
  const double done_iterations = std::max(1.0, static_cast<double>(o.iterations - start));
  for (const auto& [name, ms] : kernel_ms)
    report.kernel_ms_per_iteration.emplace_back(name, ms / done_iterations);
  report.final_eval = record.evaluations.back();
  report.evals = record.evaluations;
  report.iterations = o.iterations;
  report.start_iteration = start;
  report.wall_s = wall_s;
  report.ms_per_iteration = o.iterations > start ? 1000.0 * wall_s / (o.iterations - start) : 0.0;
  report.gaussians = model.size();
  report.peak_device_bytes = engine::Buffer::peak_bytes();
  report.peak_device_breakdown = engine::Buffer::peak_breakdown();
  report.counters = record.counters;
  report.nonfinite_pruned = record.counters.pruned_nonfinite;
  report.plane_pruned = record.counters.pruned_plane;
  report.resumes = record.resumes;
  report.growth = record.growth;
  return report;
}

// The most Gaussians the device's buffers can hold: its storage-buffer range over the widest per-Gaussian
// array (the SH coefficients), as the model's own growth caps itself (kernels/optim/trainable_gaussians.cc).
uint64_t device_row_limit(engine::Context& ctx, const kernels::GaussianModel& initial) {
  const uint64_t widest = std::max<uint64_t>(4, uint64_t{initial.sh_coeffs()} * initial.channels);
  return ctx.info().max_storage_buffer_range / (4 * widest);
}

}  // namespace

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
  if (growth.enabled) {
    if (strategy != "mcmc") bad("growth needs the mcmc strategy (ADC has no budget to grow)");
    growth.check();
  }
  parse_level_model(level_model);
  for (const auto& [name, value] : {std::pair{"level_lr_log_gain", level_lr_log_gain},
                                    {"level_lr_offset", level_lr_offset},
                                    {"level_lr_vignetting", level_lr_vignetting},
                                    {"level_lambda_identity", level_lambda_identity},
                                    {"level_lambda_smooth", level_lambda_smooth}})
    if (!(value >= 0) || !std::isfinite(value)) bad(std::string(name) + " must be finite and >= 0");
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
                  const std::function<void(const TrainProgress&)>& progress, const PlanarMap* gt_planes,
                  const std::function<void(const std::string&)>& notice_callback) {
  const std::vector<uint32_t> train_views = check_inputs(data, planes, o);
  const auto notice = [&](const std::string& line) {
    if (notice_callback)
      notice_callback(line);
    else
      std::cerr << "train: " << line << "\n";
  };
  fs::create_directories(out_dir);
  if (o.checkpoint_every > 0) fs::create_directories(out_dir / "checkpoints");

  // Device state: the rasterizer is shared by the training step and the evaluation.
  kernels::RasterizerOptions ropt;
  ropt.deterministic = o.deterministic;
  ropt.depth_gradient_to_opacity = o.geo_gradient_to_opacity;
  ropt.parameter_gradients = false;  // the fused Adam step computes them (kernels/optim/gaussian_adam.h)
  kernels::Rasterizer rasterizer(ctx, 1, ropt);
  TrainingStep training_step(ctx, data, planes, o, rasterizer);
  Evaluator evaluator(data, o, gt_planes, rasterizer);
  // A growing budget holds its validation views back from training while it grows.
  std::optional<BudgetGrowth> growth;
  std::vector<uint32_t> growth_pool = train_views;
  std::unique_ptr<TrainingData> validation_data, probe_data;
  std::unique_ptr<Evaluator> validator, probe;  // the validation views, and as many training views
  if (o.growth.enabled) {
    const std::vector<uint32_t> validation = growth_validation_views(train_views, o.growth.validation_every);
    growth.emplace(o.growth, static_cast<uint32_t>(initial.size()),
                   std::min<uint64_t>(o.max_gaussians, device_row_limit(ctx, initial)), validation.size());
    if (growth->growing() && !growth->any_phase(o))
      growth->stop("no phase ends before iteration " + std::to_string(growth->decisions_until(o)) +
                   " (the decisions' window of " + std::to_string(o.iterations) +
                   " iterations): the budget stays at its start");
    if (growth->growing()) {
      std::erase_if(growth_pool,
                    [&](uint32_t v) { return std::count(validation.begin(), validation.end(), v); });
      const auto scored = [&](const std::vector<uint32_t>& views) {
        auto d = std::make_unique<TrainingData>(data);
        for (uint32_t v = 0; v < d->views.size(); ++v)
          d->views[v].heldout = std::count(views.begin(), views.end(), v) > 0;
        return d;
      };
      validation_data = scored(validation);
      probe_data = scored(growth_training_probe_views(train_views, o.growth.validation_every));
      validator = std::make_unique<Evaluator>(*validation_data, o, nullptr, rasterizer);
      probe = std::make_unique<Evaluator>(*probe_data, o, nullptr, rasterizer);
    }
  }
  ViewSampler sampler(growth_pool, o.seed);
  RunStart run = start_run(ctx, initial, o, out_dir, run_options_json(o, data), sampler, notice,
                           [&](const RunRecord& checkpointed) {
                             if (!growth || checkpointed.growth.is_null()) return;
                             growth = BudgetGrowth::from_json(o.growth, checkpointed.growth);
                             if (!growth->growing()) sampler.set_pool(train_views);
                           });
  kernels::TrainableGaussians& model = *run.model;
  RunRecord& record = run.record;
  const uint32_t start = run.iteration;
  std::unique_ptr<kernels::McmcStrategy> mcmc;
  if (o.strategy == "mcmc") mcmc = std::make_unique<kernels::McmcStrategy>(ctx);
  DensityControl density_control(ctx, o, planes, static_cast<float>(data.scene_extent_m));
  if (growth) {
    density_control.set_budget(growth->budget());
    if (growth->growing())
      density_control.set_mcmc_growth(static_cast<float>(growth->mcmc_growth_while_growing(o.mcmc_growth)));
    record.growth = growth->to_json();
    if (start == 0 && !growth->growing()) notice("budget growth: " + growth->stop_reason());
  }
  // The level model: one row per view (held-out rows stay at identity: their level is interpolated).
  const LevelModelKind level_kind = parse_level_model(o.level_model);
  const LevelPlan level_plan(data);
  std::unique_ptr<kernels::LevelModel> level;
  if (level_kind != LevelModelKind::kNone) {
    level = std::make_unique<kernels::LevelModel>(ctx, level_plan.trained,
                                                  level_kind == LevelModelKind::kAffineVignetting);
    level->reserve(uint64_t{data.width} * data.height);
    if (o.resume) {
      if (run.level_state.empty())
        throw std::invalid_argument(
            "--resume: the checkpoint holds no level model state (it was written "
            "without one); resume with --level-model none");
      level->upload_state(run.level_state);
    }
  }
  const auto evaluate = [&](uint32_t step) {
    if (!level) return evaluator.evaluate(model.gaussians(), step);
    const LevelTable table = make_level_table(data, level_plan, level_kind, level->download_state());
    return evaluator.evaluate(model.gaussians(), step, nullptr, &table);
  };

  // Adam counts its skips per model object: this call's, on top of the checkpoint's.
  const auto adam_before = record.counters.adam_nonfinite_skips;
  const auto count_adam_skips = [&] {
    const auto now = model.nonfinite_grad_counts();
    for (uint32_t g = 0; g < kernels::kParamGroupCount; ++g)
      record.counters.adam_nonfinite_skips[g] = adam_before[g] + now[g];
  };

  double last_psnr = record.evaluations.empty() ? std::numeric_limits<double>::quiet_NaN()
                                                : record.evaluations.back().psnr_db;
  KernelTimes kernel_ms;
  const auto t0 = std::chrono::steady_clock::now();
  double wall = 0;
  for (uint32_t it = start; it < o.iterations; ++it) {
    const uint32_t step = it + 1;
    const uint32_t view = sampler.next();
    training_step.run(model, mcmc.get(), level.get(),
                      level ? level_plan.step(view, it, o) : kernels::LevelStep{}, it, view, kernel_ms,
                      record.counters);
    if (growth && growth->growing() && growth->phase_ends_at(step, o)) {
      // Judged before this step's refinement, which then grows towards the new budget.
      const auto scores = [&](Evaluator& e) {
        std::vector<double> psnr;
        for (const auto& [name, db] : e.evaluate(model.gaussians(), step).view_psnr_db) psnr.push_back(db);
        return psnr;
      };
      const double secs = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
      growth->end_phase(step, static_cast<uint32_t>(model.size()), scores(*validator), scores(*probe),
                        growth->another_phase_fits(step, o), secs);
      density_control.set_budget(growth->budget());
      if (growth->growing())
        density_control.set_mcmc_growth(static_cast<float>(growth->mcmc_growth_while_growing(o.mcmc_growth)));
      if (model.size() > growth->budget())  // a doubling rolled back
        model.load_state(keep_most_opaque(model.download_state(), growth->budget()));
      notice("budget growth at iteration " + std::to_string(step) + ": " + growth->phases().back().decision);
      if (!growth->growing()) {
        sampler.set_pool(train_views);
        density_control.set_mcmc_growth(o.mcmc_growth);
      }
      record.growth = growth->to_json();
    }
    density_control.after_step(model, mcmc.get(), step, record.counters);
    const bool last = step == o.iterations;
    if (last) wall = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
    // At the last step the final evaluation, so that a checkpoint there holds it.
    if (last || (o.eval_every > 0 && step % o.eval_every == 0)) {
      add_evaluation(record, evaluate(step));
      last_psnr = record.evaluations.back().psnr_db;
    }
    if (o.checkpoint_every > 0 && step % o.checkpoint_every == 0) {
      count_adam_skips();
      save_checkpoint(out_dir, step, sampler, model, level.get(), record);
    }
    if (progress && (step % o.progress_every == 0 || last || step == start + 1)) {
      count_adam_skips();
      const StepLosses l = training_step.last_losses();
      const double secs = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
      progress({step, o.iterations, l.total, l.photometric, l.geometric_rms_m, last_psnr, model.size(),
                (step - start) / std::max(secs, 1e-9), record.counters});
    }
  }
  if (start == o.iterations) add_evaluation(record, evaluate(o.iterations));  // nothing ran
  count_adam_skips();

  TrainReport report = make_report(record, model, o, start, wall, kernel_ms);
  const std::vector<float> level_state = level ? level->download_state() : std::vector<float>{};
  report.levels = make_level_table(data, level_plan, level_kind, level_state);
  if (level) report.level_nonfinite_skips = static_cast<uint64_t>(level_state.back());
  write_model(out_dir / "point_cloud.ply", model, data, o);
  write_level_table(out_dir / "levels.json", report.levels);
  write_metrics_json(out_dir / "metrics.json", report, data, o);
  return report;
}

}  // namespace litgs::host
