// `train --max-gaussians N|auto|search`: the model's budget as given, derived from the scene's surface
// (auto, host/train/scene_budget.h), or searched by training at growing budgets while validation PSNR still
// rises (search, host/train/budget_search.h); recorded in OUT/budget.json (a resumed run reads it back).
#pragma once

#include <Eigen/Core>
#include <cstdint>
#include <filesystem>
#include <functional>
#include <string>
#include <vector>

#include "engine/context.h"
#include "host/train/budget_search.h"
#include "host/train/lidar_planes.h"
#include "host/train/train_options.h"
#include "host/train/trainer.h"
#include "host/train/training_data.h"
#include "kernels/splat/splat_types.h"

namespace litgs::host {

struct BudgetInputs {
  const TrainingData* data = nullptr;
  const std::vector<Eigen::Vector3d>* map_points = nullptr;  // the LiDAR map (may be empty)
  const kernels::GaussianModel* initial = nullptr;           // its means stand for the surface without a map
  bool initial_is_random = false;                            // random means say nothing about the surface
  bool resume = false;
};

// `flag` is a positive integer or "auto"; std::invalid_argument naming the problem otherwise, or when auto
// has no surface to measure (no LiDAR map and a random initialization). "search" is resolved by
// search_max_gaussians; here it gives the search's cap (or, resuming, the budget it recorded). "grow" gives
// the same cap as the ceiling of a budget grown inside the training (TrainOptions::growth).
uint32_t resolve_max_gaussians(const std::string& flag, const BudgetInputs& in,
                               const std::filesystem::path& out);

// `--max-gaussians search`: trainings with `options` at growing budgets on the validation split of the
// training views, each from initial_for(budget) and in OUT/budget-search/<budget>/fold-<f>/ (with its
// trial.json once finished: host/train/budget_trial_record.h); writes OUT/budget.json and returns the budget
// found by `search`'s rule. With reuse_finished_trials, a training whose trial.json matches is not run again.
// Prints one line per budget tried; `trial_progress` (optional) gets each training's progress reports, with
// its budget and fold (0-based), at options.progress_every.
uint32_t search_max_gaussians(
    engine::Context& context, const TrainingData& data,
    const std::function<kernels::GaussianModel(uint32_t budget)>& initial_for, const PlanarMap* planes,
    const TrainOptions& options, const BudgetSearchOptions& search, const std::filesystem::path& out,
    bool reuse_finished_trials,
    const std::function<void(uint32_t budget, uint32_t fold, const TrainProgress&)>& trial_progress = {});

// `train --resume --max-gaussians search` where OUT holds no checkpoint of the final training: the run was
// cut short in the search, or after it before the final training's first checkpoint, and there is nothing
// to resume from. Then the run starts again (`resume` becomes false): at the budget OUT/budget.json recorded
// if the search had finished (`flag` becomes that count), else searching again, reusing the trainings the
// search had finished (returns true). In any other case changes nothing and returns false.
bool restart_cut_short_search(std::string& flag, bool& resume, const std::filesystem::path& out);

}  // namespace litgs::host
