#include "host/train/budget_flag.h"

#include <algorithm>
#include <cctype>
#include <cmath>
#include <fstream>
#include <iostream>
#include <nlohmann/json.hpp>
#include <optional>
#include <stdexcept>

#include "host/train/budget_search.h"
#include "host/train/budget_trial_record.h"
#include "host/train/checkpoint.h"
#include "host/train/run_options.h"
#include "host/train/scene_budget.h"
#include "host/train/trainer.h"
#include "io/atomic_file.h"

namespace litgs::host {
namespace {

uint32_t parse_count(const std::string& flag) {
  const bool digits = !flag.empty() && flag.size() <= 10 &&
                      std::all_of(flag.begin(), flag.end(), [](unsigned char c) { return std::isdigit(c); });
  const unsigned long long n = digits ? std::stoull(flag) : 0;
  if (n == 0 || n > UINT32_MAX)
    throw std::invalid_argument("--max-gaussians must be a positive integer, auto, search or grow, not '" +
                                flag + "'");
  return static_cast<uint32_t>(n);
}

uint32_t budget_of_earlier_run(const std::filesystem::path& file) {
  std::ifstream in(file);
  if (!in)
    throw std::invalid_argument("--max-gaussians auto --resume: " + file.string() +
                                " is missing (the run being resumed did not derive its budget)");
  try {
    return nlohmann::json::parse(in).at("gaussians").get<uint32_t>();
  } catch (const nlohmann::json::exception& e) {
    throw std::invalid_argument(file.string() + ": not a budget record (" + e.what() + ")");
  }
}

}  // namespace

bool restart_cut_short_search(std::string& flag, bool& resume, const std::filesystem::path& out) {
  if (!resume || flag != "search" || !newest_checkpoint(out).empty()) return false;
  resume = false;
  const std::filesystem::path record = out / "budget.json";
  if (!std::filesystem::exists(record)) return true;
  flag = std::to_string(budget_of_earlier_run(record));
  return false;
}

uint32_t resolve_max_gaussians(const std::string& flag, const BudgetInputs& in,
                               const std::filesystem::path& out) {
  const std::filesystem::path record = out / "budget.json";
  if (flag == "search") return in.resume ? budget_of_earlier_run(record) : BudgetSearchOptions{}.max_budget;
  if (flag == "grow") return BudgetSearchOptions{}.max_budget;  // the ceiling; the training grows below it
  if (flag != "auto") return parse_count(flag);
  if (in.resume) return budget_of_earlier_run(record);

  std::vector<Eigen::Vector3d> points;
  std::string source;
  if (!in.map_points->empty()) {
    points = *in.map_points;
    source = "LiDAR map";
  } else if (!in.initial_is_random && in.initial->size() > 0) {
    const std::vector<float>& m = in.initial->means;
    for (size_t i = 0; i < in.initial->size(); ++i) points.emplace_back(m[3 * i], m[3 * i + 1], m[3 * i + 2]);
    source = "initialization points";
  } else {
    throw std::invalid_argument(
        "--max-gaussians auto measures the surface from points on it: the scene has no LiDAR map and the "
        "initialization is random; give --init sfm or a point file, or a number");
  }
  const std::vector<kernels::SplatCamera> cameras = training_cameras(*in.data);

  const SceneBudgetOptions options;
  const SceneBudget b = derive_scene_budget(points, cameras, options);
  std::filesystem::create_directories(out);
  io::write_file_atomic(record, [&](std::ostream& os) {
    os << nlohmann::json{{"gaussians", b.gaussians},
                         {"source", source},
                         {"points", b.points},
                         {"points_seen", b.points_seen},
                         {"surface_m2", b.surface_m2},
                         {"surface_pixels", b.surface_pixels},
                         {"pixels_per_gaussian", options.pixels_per_gaussian},
                         {"median_footprint_m", b.median_footprint_m},
                         {"training_views", cameras.size()}}
              .dump(2)
       << "\n";
  });
  std::cout << "train: budget " << b.gaussians << " Gaussians from the scene: " << b.points_seen << " of "
            << b.points << " " << source << " seen, " << b.surface_m2
            << " m^2 of surface = " << b.surface_pixels << " pixels at the finest view, "
            << options.pixels_per_gaussian << " pixels per Gaussian\n";
  return b.gaussians;
}

uint32_t search_max_gaussians(
    engine::Context& context, const TrainingData& data,
    const std::function<kernels::GaussianModel(uint32_t budget)>& initial_for, const PlanarMap* planes,
    const TrainOptions& options, const BudgetSearchOptions& search, const std::filesystem::path& out,
    bool reuse_finished_trials,
    const std::function<void(uint32_t, uint32_t, const TrainProgress&)>& trial_progress) {
  search.check();
  std::vector<TrainingData> splits;
  for (uint32_t fold = 0; fold < search.folds; ++fold)
    splits.push_back(validation_split(data, search.validation_every, fold, search.folds));
  std::vector<size_t> validation_views;  // per fold
  for (const TrainingData& split : splits)
    validation_views.push_back(std::count_if(split.views.begin(), split.views.end(),
                                             [](const TrainingView& v) { return v.heldout; }));
  const size_t views = splits.front().views.size();
  const bool deterministic = options.deterministic || search.deterministic_trials;
  std::cout << "train: budget search on " << views << " views, " << search.folds
            << " trainings per budget, each validating on every " << search.validation_every
            << "th view from its own offset (" << validation_views.front()
            << " views; the scene's held-out views are not used), " << options.iterations
            << " iterations each" << (deterministic ? ", deterministic" : "") << "\n";
  // The seeding at the last budget asked for, so that the folds (and the first trial after the size check
  // below) share one instead of each building it (a LiDAR-map seeding fits covariances to its points).
  uint32_t cached_budget = 0;
  kernels::GaussianModel cached;
  const auto initial_at = [&](uint32_t budget) -> const kernels::GaussianModel& {
    if (cached_budget != budget) {
      cached = initial_for(budget);
      cached_budget = budget;
    }
    return cached;
  };
  const auto train_at = [&](uint32_t budget) {
    BudgetTrial trial;
    trial.initial_gaussians = static_cast<uint32_t>(initial_at(budget).size());
    uint32_t reused = 0;  // folds whose finished training an earlier, interrupted search left
    const std::string start = start_fingerprint(initial_at(budget), planes);  // every fold's
    for (uint32_t fold = 0; fold < search.folds; ++fold) {
      TrainOptions t = options;
      t.max_gaussians = budget;
      t.seed = options.seed + fold;
      t.deterministic = deterministic;
      t.resume = false;
      t.checkpoint_every = 0;
      t.eval_every = 0;  // the final evaluation only
      const std::filesystem::path dir =
          out / "budget-search" / std::to_string(budget) / ("fold-" + std::to_string(fold));
      const nlohmann::json key = {{"options", run_options_json(t, splits[fold])}, {"start", start}};
      std::optional<FinishedTrial> finished;
      if (reuse_finished_trials) finished = read_finished_trial(dir, key);
      if (finished) {
        ++reused;
      } else {
        std::function<void(const TrainProgress&)> progress;
        if (trial_progress) progress = [&](const TrainProgress& p) { trial_progress(budget, fold, p); };
        const TrainReport r = train(context, splits[fold], initial_at(budget), planes, t, dir, progress,
                                    nullptr, [](const std::string&) {});
        finished = FinishedTrial{
            r.final_eval.psnr_db, r.final_eval.ssim, {}, static_cast<uint32_t>(r.gaussians), r.wall_s};
        for (const auto& view : r.final_eval.view_psnr_db) finished->view_psnr_db.push_back(view.second);
        write_finished_trial(dir, key, *finished);
      }
      trial.fold_psnr_db.push_back(finished->psnr_db);
      trial.view_psnr_db.insert(trial.view_psnr_db.end(), finished->view_psnr_db.begin(),
                                finished->view_psnr_db.end());
      trial.psnr_db += finished->psnr_db / search.folds;
      trial.ssim += finished->ssim / search.folds;
      trial.gaussians = std::max(trial.gaussians, finished->gaussians);
      trial.wall_s += finished->wall_s;
    }
    std::cout << "train: budget " << budget << ": validation PSNR " << trial.psnr_db << " dB (folds:";
    for (double p : trial.fold_psnr_db) std::cout << " " << p;
    std::cout << "), SSIM " << trial.ssim << " (" << trial.gaussians << " Gaussians, " << trial.wall_s << " s"
              << (reused > 0 ? ", " + std::to_string(reused) + " of the trainings reused" : "")
              << (trial.initial_gaussians >= budget ? ", filled by its initialization: no plateau counted"
                                                    : "")
              << ")\n";
    return trial;
  };
  // A budget below the initialization's size (one not capped by the budget) cannot hold it: start there.
  const uint32_t smallest = static_cast<uint32_t>(initial_at(search.start).size());
  const BudgetSearchResult result = search_budget(train_at, smallest, search);
  nlohmann::json trials = nlohmann::json::array();
  for (const BudgetTrial& t : result.trials) {
    if (!t.failure.empty()) {
      trials.push_back({{"budget", t.budget}, {"failure", t.failure}});
      std::cout << "train: budget " << t.budget << " does not fit the device (" << t.failure
                << "): the search stops there\n";
      continue;
    }
    nlohmann::json trial = {{"budget", t.budget},
                            {"validation_psnr_db", t.psnr_db},
                            {"validation_psnr_db_per_fold", t.fold_psnr_db},
                            {"validation_psnr_db_per_view", t.view_psnr_db},
                            {"validation_ssim", t.ssim},
                            {"gaussians", t.gaussians},
                            {"initial_gaussians", t.initial_gaussians},
                            {"wall_s", t.wall_s}};
    if (std::isfinite(t.shortfall_db)) {
      trial["shortfall_db"] = t.shortfall_db;  // against the reference, per view
      trial["shortfall_se_db"] = t.shortfall_se_db;
    }
    trials.push_back(trial);
  }
  io::write_file_atomic(out / "budget.json", [&](std::ostream& os) {
    os << nlohmann::json{{"gaussians", result.chosen},
                         {"source", "search"},
                         {"reference", result.reference},
                         {"parsimony_se", search.parsimony_se},
                         {"min_gain_db", search.min_gain_db},
                         {"factor", search.factor},
                         {"patience", search.patience},
                         {"folds", search.folds},
                         {"deterministic_trials", deterministic},
                         {"views", views},
                         {"validation_views_per_fold", validation_views},
                         {"trials", trials}}
              .dump(2)
       << "\n";
  });
  std::cout << "train: budget " << result.reference
            << " Gaussians: the last that rose above the best before it";
  if (search.min_gain_db > 0) std::cout << " by at least " << search.min_gain_db << " dB";
  std::cout << " on the validation views";
  if (search.parsimony_se > 0)
    std::cout << "; kept " << result.chosen << ", the smallest within " << search.parsimony_se
              << " standard error(s) of it per view";
  std::cout << " (budget.json)\n";
  return result.chosen;
}

}  // namespace litgs::host
