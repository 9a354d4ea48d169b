// `train --max-gaussians grow` (MCMC): the Gaussian budget grown inside one training, instead of one training
// per budget tried (`search`, host/train/budget_search.h). The model starts at a small budget; at the end of
// each phase (BudgetGrowthOptions), once MCMC's growth has filled the budget, the validation views are
// scored, and the budget climbs the ladder start x factor^k while the validation PSNR, paired view by view
// with the last measurement, still gains more than min_gain_db (and, if asked, noise_multiple standard
// errors). Then it stops (with roll_back, back at the last budget that paid: the caller shrinks the model to
// budget()), the validation views rejoin the training views, and the remaining iterations train at that size.
// Decisions end by until_fraction of the iterations. The state is a small JSON document that checkpoints
// carry, so a training interrupted during growth resumes with the same budget, views and decisions.
#pragma once

#include <cmath>
#include <cstdint>
#include <nlohmann/json.hpp>
#include <string>
#include <vector>

#include "host/train/train_options.h"

namespace litgs::host {

struct GrowthPhase {
  uint32_t iteration = 0;                  // the step at whose end the phase was judged
  uint32_t budget = 0;                     // the budget trained in the phase
  uint32_t gaussians = 0;                  // the model's size then
  double validation_psnr_db = NAN;         // mean over the validation views; NaN: not scored (not full yet)
  double gain_db = NAN, gain_se_db = NAN;  // against the last scored phase, paired by view
  double training_psnr_db = NAN, training_gain_db = NAN;  // the training views scored beside them
  double wall_s = 0;                                      // since this call of train started
  std::string decision;                                   // grow, wait, or stop, and why
};

class BudgetGrowth {
 public:
  // `ceiling`: the largest budget allowed (the user's --max-gaussians cap, or what the device can hold).
  // `validation_views`: how many views validate; fewer than two cannot measure the noise, and growth stops
  // at once (said in stop_reason()).
  BudgetGrowth(const BudgetGrowthOptions& options, uint32_t initial_gaussians, uint32_t ceiling,
               size_t validation_views);

  uint32_t budget() const { return budget_; }
  bool growing() const { return stop_reason_.empty(); }
  const std::string& stop_reason() const { return stop_reason_; }
  const std::vector<GrowthPhase>& phases() const { return phases_; }

  // Whether `step` (1-based, before its refinement) ends a phase: every phase_refinements-th refinement step
  // of `train` (the densification window and cadence) up to until_fraction of the iterations.
  // `another_phase_fits`: whether a phase after it would still end inside that window.
  bool phase_ends_at(uint32_t step, const TrainOptions& train) const;
  bool another_phase_fits(uint32_t step, const TrainOptions& train) const;
  // Whether any phase ends inside the decisions' window (a short training has none: its budget stays).
  bool any_phase(const TrainOptions& train) const;

  // The decision at a phase's end: the validation views' and the training views' PSNR, each in the same
  // view order every time.
  void end_phase(uint32_t step, uint32_t gaussians, const std::vector<double>& validation_psnr_db,
                 const std::vector<double>& training_psnr_db, bool another_phase_fits, double wall_s);
  // Stops growing for a reason found outside the rule (the device's limits).
  void stop(const std::string& reason);
  // MCMC's growth per refinement while it grows: at least `mcmc_growth`, and enough that the model fills the
  // current budget from its size at the last phase's end (a budget raised by `factor` before any) within a
  // phase's refinements. Changes with each phase: the caller sets it again after end_phase.
  double mcmc_growth_while_growing(double mcmc_growth) const;
  // The first step at which no phase ends any more: the densification window's end or until_fraction of the
  // iterations, whichever comes first.
  uint32_t decisions_until(const TrainOptions& train) const;

  // The checkpoint's and metrics.json's form; from_json throws nlohmann::json::exception on a bad document.
  nlohmann::json to_json() const;
  static BudgetGrowth from_json(const BudgetGrowthOptions& options, const nlohmann::json& j);

 private:
  // The budget after the current one: the first rung of start x factor^k at least sqrt(factor) above it,
  // where fixed budgets and the search are measured, so that an initialization between two rungs climbs to
  // a rung rather than doubling past it (docs/budget.md: doubling from the initialization overshot the
  // facade's best fixed budget), nor spends a phase on a small step.
  uint64_t next_budget() const;
  // The next doubling's gain from the last one (not yet in phases_) and the one before: last * (last /
  // before) when the gains fall, else half the last; NaN unless the last gained.
  double extrapolated_gain(double last_gain) const;

  BudgetGrowthOptions options_;
  uint32_t budget_ = 0, ceiling_ = 0;
  std::string stop_reason_;
  std::vector<GrowthPhase> phases_;
  std::vector<double> last_scored_, last_training_;  // the last scored phase's per-view PSNR
  uint32_t last_scored_budget_ = 0;                  // that phase's budget: where a roll-back returns
};

// The validation views of a growing training: every validation_every-th of `train_views`, from the middle
// of the first stride (as the budget search's first fold); the training views scored beside them: as many,
// each the training view after one.
std::vector<uint32_t> growth_validation_views(const std::vector<uint32_t>& train_views,
                                              uint32_t validation_every);
std::vector<uint32_t> growth_training_probe_views(const std::vector<uint32_t>& train_views,
                                                  uint32_t validation_every);

}  // namespace litgs::host
