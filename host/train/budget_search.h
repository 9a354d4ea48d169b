// `train --max-gaussians search`: the Gaussian budget a scene needs, found by growing while held-out error
// still falls. Each budget, growing by `factor`, is trained `folds` times for the full iterations, each on
// the training views less its own validation subset (every `validation_every`-th training view from the
// fold's offset; the scene's own held-out views are not used), and scored by the folds' mean validation PSNR;
// the search stops once a budget does not rise above the best so far (by `min_gain_db`, 0 by default) and
// `patience` more budgets do not either, and keeps the last budget that did: a fixed budget the user must
// guess is replaced by the smallest one that the views show still pays. Each budget's shortfall against it,
// per validation view (paired), is recorded with its standard error; with parsimony_se > 0 the smallest
// budget within that many standard errors is kept instead (at 1, the one-standard-error rule of
// cross-validation: Breiman et al. 1984; Hastie, Tibshirani and Friedman, ESL 7.10). The final training then
// runs at the budget kept on every training view. Costs `folds` trainings per budget tried; the trials are
// deterministic, so a search repeated with the same options and seed on the same device keeps the same
// budget.
#pragma once

#include <cmath>
#include <cstdint>
#include <functional>
#include <string>
#include <vector>

#include "host/train/training_data.h"

namespace litgs::host {

struct BudgetSearchOptions {
  uint32_t start = 5000;  // the first budget (raised to the initialization's size where larger)
  double factor = 2.0;    // each budget is this times the last
  // A larger budget counts as a gain only if its score rises above the best so far by at least this much;
  // 0 (any rise): "grow while held-out error still falls". A margin (0.1 dB, the default until issue 15
  // dropped it) stopped some of the recorded searches a doubling before their validation stopped rising,
  // below their scene's best fixed budget, and none went past it (docs/budget.md has the replay).
  double min_gain_db = 0.0;
  // Budgets tried past one that did not gain before the search stops: 1 looks one doubling past a plateau
  // (a budget that gains nothing can precede one that does: the facade at 20k).
  uint32_t patience = 1;
  uint32_t max_budget = 4000000;  // the MCMC strategy's row limit
  uint32_t validation_every = 8;  // every k-th training view validates (at least one)
  // Trainings per budget, each validating on its own every-k-th of the views (validation_split's fold) with
  // its own seed; their mean validation PSNR scores the budget. One fold of a few views is a noisy score:
  // it ranked budgets otherwise than the test views did (docs/budget.md); more folds cost one training each.
  uint32_t folds = 2;
  // Standard errors of shortfall a smaller budget may have against the last one that gained and still be
  // chosen (1: the one-standard-error rule); 0 keeps the last budget that gained. 0 by default: at 1 the
  // facade's search chose 160k, which scored below its 320k on the test views, and DUNR's and the street's
  // choices did not change (docs/budget.md).
  double parsimony_se = 0.0;
  // Trials train with bit-identical gradients, so that one command keeps one budget: with float atomics the
  // same trial's score moved between runs by as much as two neighbouring budgets differ, and DUNR's search
  // kept 40k in one run and 80k in another (docs/budget.md). Ordered sums make each trial somewhat slower
  // (docs/experiments.md, "deterministic trials", issue 18). The final training follows
  // `train --deterministic` as any other.
  bool deterministic_trials = true;
  void check() const;  // throws std::invalid_argument naming the bad field
};

struct BudgetTrial {
  uint32_t budget = 0;
  double psnr_db = 0;                // on the validation views (the folds' mean)
  std::vector<double> fold_psnr_db;  // each fold's
  // Each validation view's, the folds' views in order: the same views in every trial, so trials pair up.
  std::vector<double> view_psnr_db;
  // Against the reference (the last budget that gained): the mean per-view PSNR it lacks and that mean's
  // standard error; NaN where not measured (fewer than two paired views).
  double shortfall_db = NAN;
  double shortfall_se_db = NAN;
  double ssim = 0;
  uint32_t gaussians = 0;  // the model's size at the end
  // The initialization's size (the budget caps it). One that fills the budget leaves MCMC no room to grow:
  // the model is a subsample of the seeding points, not what the images ask for.
  uint32_t initial_gaussians = 0;
  double wall_s = 0;
  std::string failure;  // why the budget could not be trained (the device's memory or buffer limits)
};

struct BudgetSearchResult {
  uint32_t chosen = 0;
  uint32_t reference = 0;           // the last budget that gained; chosen is at most this
  std::vector<BudgetTrial> trials;  // in the order run
};

// The search's rule over `train_at(budget)` (the budget's trainings on the validation splits, scored). The
// first trial sets the baseline; the next ones run until patience + 1 budgets in a row fail to gain
// min_gain_db over the best before them (a budget its initialization filled is not counted: its score
// measures how densely the seeding points were subsampled, not whether the images ask for more Gaussians;
// the facade through `run`, seeded from more LiDAR points than its first budgets hold, stopped on a plateau
// of such budgets: docs/budget.md), or until a trial ends with fewer Gaussians than its budget (a larger
// budget would train the same model: MCMC's growth in the given iterations, not the budget, limited it). A
// budget the device cannot hold (train_at throws std::length_error, as buffers over the device's memory or
// limits do) ends the search at the budget before it, recorded as a failed trial; at the first budget it
// passes through. The shortfalls are filled and chosen is the smallest budget up to the reference within
// parsimony_se standard errors of it (choose_within_standard_errors; the reference at 0).
// std::invalid_argument for bad options; anything else train_at throws passes through.
BudgetSearchResult search_budget(const std::function<BudgetTrial(uint32_t budget)>& train_at,
                                 uint32_t initial_gaussians, const BudgetSearchOptions& options = {});

// Fills each trial's shortfall against trials[reference] from their paired view_psnr_db and returns the index
// of the smallest budget (of those tried, up to the reference's) whose mean shortfall is at most
// `se_multiple` times its standard error (at 0, the reference: only the shortfalls are filled). A trial whose
// views do not pair with the reference's (missing, a different count, a failed trial) or fewer than two views
// is never chosen over the reference.
size_t choose_within_standard_errors(std::vector<BudgetTrial>& trials, size_t reference, double se_multiple);

// The data the search trains on: the scene's held-out views dropped, and every validation_every-th of the
// remaining views held out instead, counted from the middle of the first stride for fold 0 and shifted by
// validation_every / folds per fold, so that the folds' validation views are disjoint.
// std::invalid_argument when fewer than two training views remain to split, or fold >= folds.
TrainingData validation_split(const TrainingData& data, uint32_t validation_every, uint32_t fold = 0,
                              uint32_t folds = 1);

}  // namespace litgs::host
