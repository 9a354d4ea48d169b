#include "host/train/budget_search.h"

#include <algorithm>
#include <cmath>
#include <stdexcept>

namespace litgs::host {

void BudgetSearchOptions::check() const {
  auto bad = [](const std::string& what) { throw std::invalid_argument("BudgetSearchOptions." + what); };
  if (start == 0) bad("start must be positive");
  if (!(factor > 1.0) || !std::isfinite(factor)) bad("factor must be above 1");
  if (!(min_gain_db >= 0.0) || !std::isfinite(min_gain_db)) bad("min_gain_db must be 0 or more");
  if (max_budget < start) bad("max_budget must be at least start");
  if (validation_every < 2) bad("validation_every must be at least 2");
  if (folds < 1 || folds > validation_every) bad("folds must be between 1 and validation_every");
  if (!(parsimony_se >= 0.0) || !std::isfinite(parsimony_se)) bad("parsimony_se must be 0 or more");
}

BudgetSearchResult search_budget(const std::function<BudgetTrial(uint32_t budget)>& train_at,
                                 uint32_t initial_gaussians, const BudgetSearchOptions& o) {
  o.check();
  BudgetSearchResult result;
  uint32_t budget = std::min(std::max(o.start, initial_gaussians), o.max_budget);
  double best = -INFINITY;
  size_t reference = 0;  // the trial of the last budget that gained
  uint32_t misses = 0;   // budgets in a row that did not gain
  for (;;) {
    BudgetTrial t;
    try {
      t = train_at(budget);
    } catch (const std::length_error& e) {
      if (result.trials.empty()) throw;
      t = BudgetTrial{};
      t.psnr_db = NAN;
      t.failure = e.what();
    }
    t.budget = budget;
    result.trials.push_back(t);
    // A NaN score never counts as a gain, nor a tie (at min_gain_db 0 a gain is any rise); a budget the
    // device cannot hold ends the search.
    if (t.psnr_db >= best + o.min_gain_db && t.psnr_db > best) {
      best = t.psnr_db;
      reference = result.trials.size() - 1;
      misses = 0;
    } else if (!t.failure.empty()) {
      break;
    } else if (t.initial_gaussians < budget && ++misses > o.patience) {
      break;  // a budget its initialization filled does not count as a miss
    }
    // A budget the training did not fill (MCMC's growth ends below it) ends the search: a larger one would
    // train the same model again.
    if (t.failure.empty() && t.gaussians > 0 && t.gaussians < budget) break;
    if (budget >= o.max_budget) break;
    budget = static_cast<uint32_t>(std::min<double>(std::ceil(budget * o.factor), o.max_budget));
  }
  // reference stays 0 where the first trial scored NaN.
  result.reference = result.trials[reference].budget;
  result.chosen =
      result.trials[choose_within_standard_errors(result.trials, reference, o.parsimony_se)].budget;
  return result;
}

size_t choose_within_standard_errors(std::vector<BudgetTrial>& trials, size_t reference, double se_multiple) {
  const std::vector<double>& ref = trials.at(reference).view_psnr_db;
  if (ref.size() < 2) return reference;  // no standard error from fewer views
  const double n = static_cast<double>(ref.size());
  size_t chosen = reference;
  for (size_t i = 0; i < trials.size(); ++i) {
    BudgetTrial& t = trials[i];
    if (!t.failure.empty() || t.view_psnr_db.size() != ref.size()) continue;
    double mean = 0, squares = 0;
    for (size_t v = 0; v < ref.size(); ++v) mean += (ref[v] - t.view_psnr_db[v]) / n;
    for (size_t v = 0; v < ref.size(); ++v) squares += std::pow(ref[v] - t.view_psnr_db[v] - mean, 2);
    t.shortfall_db = mean;
    t.shortfall_se_db = std::sqrt(squares / (n - 1) / n);
    // Written so that a NaN view never qualifies a budget.
    const bool within = mean <= se_multiple * t.shortfall_se_db;
    if (i < chosen && within && se_multiple > 0) chosen = i;
  }
  return chosen;
}

TrainingData validation_split(const TrainingData& data, uint32_t every, uint32_t fold, uint32_t folds) {
  if (every < 2) throw std::invalid_argument("validation_split: every must be at least 2");
  if (folds < 1 || folds > every || fold >= folds)
    throw std::invalid_argument("validation_split: fold " + std::to_string(fold) + " of " +
                                std::to_string(folds) + " folds with every " + std::to_string(every));
  TrainingData out = data;
  out.views.clear();
  for (const TrainingView& v : data.views)
    if (!v.heldout) out.views.push_back(v);
  if (out.views.size() < 2)
    throw std::invalid_argument("the budget search needs at least two training views to hold one out, has " +
                                std::to_string(out.views.size()));
  const size_t offset = (every / 2 + fold * (every / folds)) % every;
  bool any = false;
  for (size_t i = 0; i < out.views.size(); ++i) any |= out.views[i].heldout = i % every == offset;
  // Fewer views than the offset + 1: one view per fold, spread over the list.
  if (!any) out.views[(out.views.size() / 2 + fold) % out.views.size()].heldout = true;
  return out;
}

}  // namespace litgs::host
