// `litgs-engine train SCENE --out DIR ...`: a Gaussian map of a scene directory, on the Vulkan device.
#include <unistd.h>

#include <CLI/CLI.hpp>
#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <iostream>
#include <memory>
#include <nlohmann/json.hpp>
#include <string>
#include <vector>

#include "engine/context.h"
#include "host/train/budget_flag.h"
#include "host/train/initial_model.h"
#include "host/train/lidar_planes.h"
#include "host/train/scene_budget.h"
#include "host/train/train_option_names.h"
#include "host/train/trainer.h"
#include "host/train/training_data.h"
#include "host/train/true_planes.h"
#include "io/scene.h"
#include "tools/commands.h"
#include "tools/data_flags.h"

namespace litgs::tools {
namespace {

struct TrainCliOptions {
  std::string scene, out;
  host::InitialModelOptions initial;  // --init and its options (seed and SH degree from `train`)
  DataFlags data_flags;               // --intensity, --poses
  std::string trace;                  // JSON lines appended at every progress report (the report's curves)
  std::string max_gaussians = host::train_defaults::kMaxGaussians;
  host::BudgetSearchOptions budget_search;
  std::vector<std::string> search_options_given;  // the --budget-* options on the command line
  std::vector<std::string> growth_options_given;  // the --growth-* options on the command line
  host::TrainingDataOptions data;
  host::TrainOptions train;
};

// The counters of events that should not happen (host/train/run_record.h), only those that did: "" in a
// healthy run.
std::string anomaly_text(const host::TrainingCounters& c) {
  std::string s;
  if (c.adam_nonfinite_total() > 0) {
    s += "  adam non-finite skips " + std::to_string(c.adam_nonfinite_total()) + " (";
    bool first = true;
    for (uint32_t g = 0; g < kernels::kParamGroupCount; ++g)
      if (c.adam_nonfinite_skips[g] > 0) {
        s += std::string(first ? "" : ", ") + kernels::kParamGroupNames[g] + " " +
             std::to_string(c.adam_nonfinite_skips[g]);
        first = false;
      }
    s += ")";
  }
  if (c.culled_nonfinite > 0) s += "  culled non-finite " + std::to_string(c.culled_nonfinite);
  if (c.walks_cut_short > 0) s += "  walks cut short " + std::to_string(c.walks_cut_short);
  return s;
}

std::string format_eta(double s) {
  if (!std::isfinite(s) || s < 0) return "?";
  char buf[32];
  std::snprintf(buf, sizeof buf, "%d:%02d", static_cast<int>(s) / 60, static_cast<int>(s) % 60);
  return buf;
}

// One progress report: iteration, losses, last PSNR, Gaussians, speed, ETA and any anomaly.
std::string progress_text(const host::TrainProgress& p) {
  const double eta = (p.total - p.iteration) / std::max(p.iterations_per_s, 1e-9);
  char terms[64] = "";
  if (std::isfinite(p.geometric_rms_m))
    std::snprintf(terms, sizeof terms, " (pho %.4f, plane rms %.1f cm)", p.photometric_loss,
                  100 * p.geometric_rms_m);
  char line[320];
  std::snprintf(line, sizeof line, "[%6u/%u] loss %.4f%s  psnr %s  gaussians %zu  %.2f it/s  eta %s",
                p.iteration, p.total, p.loss, terms,
                std::isfinite(p.psnr_db) ? std::to_string(p.psnr_db).substr(0, 5).c_str() : "-", p.gaussians,
                p.iterations_per_s, format_eta(eta).c_str());
  return line + anomaly_text(p.counters);
}

void run_train(TrainCliOptions o) {
  // Refused when given at all, not when its value differs from the default: an ignored option is a surprise.
  if (!o.search_options_given.empty() && o.max_gaussians != "search")
    throw std::invalid_argument(o.search_options_given.front() +
                                " applies to --max-gaussians search only, not '" + o.max_gaussians + "'");
  if (!o.growth_options_given.empty() && o.max_gaussians != "grow")
    throw std::invalid_argument(o.growth_options_given.front() +
                                " applies to --max-gaussians grow only, not '" + o.max_gaussians + "'");
  const bool asked_to_resume = o.train.resume;
  const bool reuse_finished_trials = host::restart_cut_short_search(o.max_gaussians, o.train.resume, o.out);
  if (reuse_finished_trials)
    std::cout
        << "train: --resume: the budget search had not finished; it continues, reusing the trainings it "
           "finished\n";
  else if (asked_to_resume && !o.train.resume)
    std::cout << "train: --resume: no checkpoint of the final training yet; it starts again at the searched "
                 "budget, "
              << o.max_gaussians << " Gaussians (budget.json)\n";
  apply_data_flags(o.data_flags, o.data);
  o.train.growth.enabled = o.max_gaussians == "grow";
  o.train.check();
  const host::TrainingData data = host::load_training_data(o.scene, o.data);

  // The LiDAR map, when the scene has one: the geometric loss's planes and the default initialization.
  std::vector<Eigen::Vector3d> map_points;
  io::SceneReadOptions read;
  read.check_images = false;
  const io::Scene scene = io::read_scene(o.scene, read);
  if (scene.map) map_points = scene.map->positions;
  o.initial.seed = o.train.seed;
  o.initial.sh_degree = o.train.sh_degree;
  const host::InitialModel initial(o.initial, o.scene, map_points, o.train.resume);
  const bool init_from_map = initial.from_map();
  std::unique_ptr<host::PlanarMap> planes;
  if ((o.train.lambda_geo > 0 || init_from_map) && !map_points.empty())
    planes = std::make_unique<host::PlanarMap>(host::fit_planes(map_points, host::PlaneFitOptions{}));
  if (o.train.lambda_geo > 0 && !planes) {
    std::cerr << "train: the scene has no LiDAR map; training photometric only (lambda_geo 0)\n";
    o.train.lambda_geo = 0;
  }

  // Ground truth planes (synthetic scenes): evaluation's depth residual.
  const std::unique_ptr<host::PlanarMap> gt_planes = host::true_planar_map(scene);

  // The budget: `auto` measures the LiDAR map when there is one (then it is known before the map
  // initialization, which it caps), else the initialization's points.
  host::BudgetInputs budget;
  budget.data = &data;
  budget.map_points = &map_points;
  budget.resume = o.train.resume;
  const bool budget_from_map = !map_points.empty();
  if (budget_from_map) o.train.max_gaussians = host::resolve_max_gaussians(o.max_gaussians, budget, o.out);

  const auto initialize = [&](uint32_t cap_gaussians, std::string& init_what) {
    kernels::GaussianModel model = initial.make(data, planes.get(), cap_gaussians, init_what);
    if (initial.source() == host::InitialSource::kCheckpoint) init_what += " in " + o.out;
    return model;
  };
  // A searched budget caps a LiDAR-map seeding only once it is known: that one is made after the search.
  const bool search = o.max_gaussians == "search" && !o.train.resume;
  std::string init_what;
  kernels::GaussianModel model;
  if (!(search && init_from_map)) model = initialize(o.train.max_gaussians, init_what);

  if (!budget_from_map) {
    budget.initial = &model;
    budget.initial_is_random = initial.source() == host::InitialSource::kRandom;
    o.train.max_gaussians = host::resolve_max_gaussians(o.max_gaussians, budget, o.out);
  }
  o.train.check();

  engine::Context context;
  const bool tty = ::isatty(STDOUT_FILENO);
  if (search) {
    // Each trial's progress, as the final training's below: a trial can take minutes to hours on a CPU
    // device.
    const auto trial_progress = [&](uint32_t trial_budget, uint32_t fold, const host::TrainProgress& p) {
      std::cout << (tty ? "\r" : "") << "budget " << trial_budget << " fold " << fold + 1 << "/"
                << o.budget_search.folds << " " << progress_text(p)
                << (tty && p.iteration < p.total ? "" : "\n") << std::flush;
    };
    o.train.max_gaussians = host::search_max_gaussians(
        context, data,
        [&](uint32_t trial_budget) {
          std::string what;
          return initialize(trial_budget, what);
        },
        planes.get(), o.train, o.budget_search, o.out, reuse_finished_trials, trial_progress);
    o.train.check();
    if (init_from_map) model = initialize(o.train.max_gaussians, init_what);
  }
  std::cout << "train: " << data.views.size() << " views (" << data.width << "x" << data.height << ", "
            << data.frozen_skipped << " frozen skipped), "
            << (o.train.resume ? "resuming from "
                               : "init " + std::to_string(model.size()) + " Gaussians from ")
            << init_what << ", lambda_geo " << o.train.lambda_geo << ", on " << context.info().name << "\n";
  auto progress = [&](const host::TrainProgress& p) {
    std::cout << (tty ? "\r" : "") << progress_text(p) << (tty ? "" : "\n") << std::flush;
  };
  // --trace: one JSON object per progress report, appended and flushed, so that what an interrupted run
  // reported survives it. session_s counts from this call's start (a resume starts a new session).
  std::ofstream trace;
  if (!o.trace.empty()) {
    const std::filesystem::path parent = std::filesystem::path(o.trace).parent_path();
    if (!parent.empty()) std::filesystem::create_directories(parent);
    trace.open(o.trace, std::ios::app);
    if (!trace) throw std::runtime_error(o.trace + ": cannot open the trace file for appending");
  }
  const auto session_start = std::chrono::steady_clock::now();
  auto report = [&](const host::TrainProgress& p) {
    progress(p);
    if (!trace.is_open()) return;
    const double session_s =
        std::chrono::duration<double>(std::chrono::steady_clock::now() - session_start).count();
    const auto number = [](double v) {
      return std::isfinite(v) ? nlohmann::json(v) : nlohmann::json(nullptr);
    };
    trace << nlohmann::json{{"iteration", p.iteration},     {"session_s", session_s},
                            {"loss", number(p.loss)},       {"photometric_loss", number(p.photometric_loss)},
                            {"psnr_db", number(p.psnr_db)}, {"geometric_rms_m", number(p.geometric_rms_m)},
                            {"gaussians", p.gaussians}}
                 .dump()
          << "\n"
          << std::flush;
  };
  // Resume notes and warnings on their own line, not inside a progress line being redrawn.
  auto notice = [&](const std::string& line) { std::cerr << "train: " << line << "\n"; };
  const host::TrainReport r =
      host::train(context, data, model, planes.get(), o.train, o.out, report, gt_planes.get(), notice);
  if (tty) std::cout << "\n";
  std::cout << "train: " << r.iterations << " iterations in " << r.wall_s << " s (" << r.ms_per_iteration
            << " ms/iteration), " << r.gaussians << " Gaussians; held-out PSNR " << r.final_eval.psnr_db
            << " dB, SSIM " << r.final_eval.ssim << ", MAE " << r.final_eval.mae_counts << " counts";
  if (r.final_eval.leveled)
    std::cout << " (at interpolated levels; at identity " << r.final_eval.psnr_identity_db << " dB, "
              << r.final_eval.mae_counts_identity << " counts)";
  std::cout << "; wrote " << o.out << "/point_cloud.ply ("
            << (o.train.recentred_output ? "recentred scene frame" : "original world frame")
            << "), levels.json and metrics.json\n";
  if (r.counters.any_anomaly())
    std::cout << "train: counters:" << anomaly_text(r.counters) << " (metrics.json)\n";
}

}  // namespace

void add_train_command(CLI::App& app) {
  namespace T = host::train_option;
  auto o = std::make_shared<TrainCliOptions>();
  CLI::App* cmd = app.add_subcommand("train", "Train a Gaussian map of a scene directory on the device");
  cmd->add_option("scene", o->scene, "Scene directory (docs/scene-format.md)")
      ->required()
      ->check(CLI::ExistingDirectory);
  cmd->add_option("--out", o->out, "Output directory (point_cloud.ply, metrics.json, checkpoints/)")
      ->required();
  cmd->add_option(T::kIterations.flag, o->train.iterations, T::kIterations.help)->capture_default_str();
  add_data_flags(cmd, o->data, o->data_flags);
  cmd->add_option(T::kLambdaGeo.flag, o->train.lambda_geo, T::kLambdaGeo.help)->capture_default_str();
  cmd->add_option("--geo-robust-scale", o->train.geo_robust_scale_m,
                  "Cauchy scale of the point-to-plane residual, metres (0: squared residuals)")
      ->capture_default_str();
  cmd->add_flag("!--geo-no-opacity-gradient", o->train.geo_gradient_to_opacity,
                "The LiDAR term moves Gaussians but leaves their opacity to the image");
  cmd->add_option("--lambda-ssim", o->train.lambda_ssim, "Weight of D-SSIM in the photometric loss")
      ->capture_default_str();
  cmd->add_option(T::kInit.flag, o->initial.init, T::kInit.help)->capture_default_str();
  cmd->add_option_function<std::string>(
         "--init-frame", [o](const std::string& frame) { o->initial.init_in_scene_frame = frame == "scene"; },
         "--init FILE's frame: world (the original, scene + world_offset_m) or scene (recentred, as the "
         "front end's and refine's points)")
      ->check(CLI::IsMember({"world", "scene"}));
  cmd->add_option("--init-flatness", o->initial.init_flatness,
                  "LiDAR-map init: thickness / radius of the discs on LiDAR planes (1: spheres)")
      ->check(CLI::Range(1e-3, 1.0))
      ->capture_default_str();
  cmd->add_option("--random-count", o->initial.random_count, "Gaussians of --init random")
      ->capture_default_str();
  cmd->add_option(
         "--max-init-points", o->initial.max_init_points,
         "LiDAR-map initialization: at most this many of the map points the training views see (a seeded "
         "random subset; never more than --max-gaussians)")
      ->check(CLI::PositiveNumber)
      ->capture_default_str();
  cmd->add_option(T::kEvalEvery.flag, o->train.eval_every, T::kEvalEvery.help);
  cmd->add_option(T::kCheckpointEvery.flag, o->train.checkpoint_every, T::kCheckpointEvery.help);
  cmd->add_flag(
      "--resume", o->train.resume,
      "Continue from the newest checkpoint in --out, with its options (only --iterations, --eval-every, "
      "--checkpoint-every, --progress-every, --recentred-output may change)");
  cmd->add_flag(
      "--recentred-output", o->train.recentred_output,
      "Write point_cloud.ply in the scene's recentred frame (poses.txt's) instead of the original world "
      "frame (scene + world_offset_m)");
  cmd->add_option(T::kMaxGaussians.flag, o->max_gaussians, T::kMaxGaussians.help)->capture_default_str();
  cmd->add_option("--budget-parsimony", o->budget_search.parsimony_se,
                  "With --max-gaussians search: keep the smallest budget whose validation PSNR, paired per "
                  "view, lacks at most this many standard errors against the last budget that gained (1: the "
                  "one-standard-error rule; 0: that budget)")
      ->check(CLI::NonNegativeNumber)
      ->capture_default_str();
  cmd->add_option("--budget-min-gain", o->budget_search.min_gain_db,
                  "With --max-gaussians search: dB of validation PSNR a budget must add over the best before "
                  "it to count as a gain (0: any rise; 0.1 was the default until 2026-11-27)")
      ->check(CLI::NonNegativeNumber)
      ->capture_default_str();
  cmd->add_option(
         "--budget-folds", o->budget_search.folds,
         "With --max-gaussians search: trainings per budget, each validating on its own eighth of the "
         "training views (8: every training view validates once; each fold costs one training)")
      ->check(CLI::Range(1, 8))
      ->capture_default_str();
  host::BudgetGrowthOptions& growth = o->train.growth;
  cmd->add_option("--growth-start", growth.start,
                  "With --max-gaussians grow: the first budget (raised to the initialization's size)")
      ->check(CLI::PositiveNumber)
      ->capture_default_str();
  cmd->add_option(
         "--growth-phase", growth.phase_refinements,
         "With --max-gaussians grow: refinements per phase (MCMC's growth is raised while it grows so "
         "that a doubled budget fills within one)")
      ->check(CLI::Range(1, 100))
      ->capture_default_str();
  cmd->add_option(
         "--growth-until", growth.until_fraction,
         "With --max-gaussians grow: decisions end by this share of --iterations (the rest trains at "
         "the final size on every training view)")
      ->check(CLI::Range(0.01, 1.0))
      ->capture_default_str();
  cmd->add_option("--growth-validation-every", growth.validation_every,
                  "With --max-gaussians grow: every Nth training view validates (held back while it grows)")
      ->check(CLI::Range(2, 1000))
      ->capture_default_str();
  cmd->add_option("--growth-min-gain", growth.min_gain_db,
                  "With --max-gaussians grow: dB of validation PSNR a doubling must add to grow again")
      ->check(CLI::NonNegativeNumber)
      ->capture_default_str();
  cmd->add_option("--growth-noise-multiple", growth.noise_multiple,
                  "With --max-gaussians grow: standard errors of the paired gain it must also exceed (0: "
                  "the mean decides)")
      ->check(CLI::NonNegativeNumber)
      ->capture_default_str();
  cmd->add_option("--growth-min-transfer", growth.min_transfer,
                  "With --max-gaussians grow: the validation gain must be at least this share of the "
                  "training views' (0: not asked)")
      ->check(CLI::NonNegativeNumber)
      ->capture_default_str();
  cmd->add_flag(
      "--growth-no-last-doubling", [o](int64_t) { o->train.growth.last_doubling = false; },
      "With --max-gaussians grow: at the decisions' window's end, no unjudged doubling even when the "
      "extrapolated gain would pay");
  cmd->add_flag(
      "--growth-no-roll-back", [o](int64_t) { o->train.growth.roll_back = false; },
      "With --max-gaussians grow: keep the doubling that did not pay instead of returning to the "
      "last budget that did");
  cmd->add_option(T::kStrategy.flag, o->train.strategy, T::kStrategy.help)
      ->check(CLI::IsMember({"adc", "mcmc"}))
      ->capture_default_str();
  cmd->add_option(T::kMcmcGrowth.flag, o->train.mcmc_growth, T::kMcmcGrowth.help)->capture_default_str();
  cmd->add_option("--mcmc-noise-lr", o->train.mcmc_noise_lr, "MCMC: position noise x means learning rate")
      ->capture_default_str();
  cmd->add_flag("--deterministic", o->train.deterministic, "Bit-identical gradients (slower)");
  cmd->add_option("--sh-degree", o->train.sh_degree, "Final SH degree")->capture_default_str();
  cmd->add_option(T::kSeed.flag, o->train.seed, T::kSeed.help)->capture_default_str();
  cmd->add_option("--plane-prune-k", o->train.plane_prune_k,
                  "Prune Gaussians beyond median + k * 1.4826 * MAD of their LiDAR-plane distances (at least "
                  "10 cm; 0: off)")
      ->capture_default_str();
  cmd->add_option("--densify-from", o->train.densify_from, "First densification iteration")
      ->capture_default_str();
  cmd->add_option("--densify-until", o->train.densify_until, "Last densification iteration")
      ->capture_default_str();
  cmd->add_option("--densify-every", o->train.densify_every, "Densification cadence")->capture_default_str();
  cmd->add_option("--densify-grad-threshold", o->train.densify_grad_threshold,
                  "Densify where the screen-space gradient of the total loss exceeds this (3DGS units; not "
                  "scaled by 1 - lambda_geo)")
      ->capture_default_str();
  cmd->add_option("--opacity-reset-every", o->train.opacity_reset_every, "Opacity reset cadence")
      ->capture_default_str();
  cmd->add_option("--trace", o->trace,
                  "Append each progress report (iteration, seconds, loss, Gaussians) as a JSON line to FILE");
  cmd->add_option(T::kProgressEvery.flag, o->train.progress_every, T::kProgressEvery.help)
      ->capture_default_str();
  cmd->add_option("--level-model", o->train.level_model,
                  "Radiometric level per frame, learnt with the map: none, affine (gain and offset per "
                  "frame) or affine-vignetting (and a vignetting shared by all frames)")
      ->check(CLI::IsMember({"none", "affine", "affine-vignetting"}))
      ->capture_default_str();
  cmd->add_option("--level-lr-gain", o->train.level_lr_log_gain, "Level model: Adam rate of the log-gains")
      ->capture_default_str();
  cmd->add_option("--level-lr-offset", o->train.level_lr_offset, "Level model: Adam rate of the offsets")
      ->capture_default_str();
  cmd->add_option("--level-lr-vignetting", o->train.level_lr_vignetting,
                  "Level model: Adam rate of the vignetting")
      ->capture_default_str();
  cmd->add_option("--level-lambda-identity", o->train.level_lambda_identity,
                  "Level model: weight of the pull toward identity")
      ->capture_default_str();
  cmd->add_option("--level-lambda-smooth", o->train.level_lambda_smooth,
                  "Level model: weight of the pull toward the neighbouring frames' level")
      ->capture_default_str();
  cmd->callback([cmd, o] {
    for (const char* name : {"--budget-parsimony", "--budget-min-gain", "--budget-folds"})
      if (cmd->count(name) > 0) o->search_options_given.push_back(name);
    for (const char* name : {"--growth-start", "--growth-phase", "--growth-until",
                             "--growth-validation-every", "--growth-min-gain", "--growth-noise-multiple",
                             "--growth-min-transfer", "--growth-no-roll-back", "--growth-no-last-doubling"})
      if (cmd->count(name) > 0) o->growth_options_given.push_back(name);
    run_train(*o);
  });
}

}  // namespace litgs::tools
