#include "host/train/budget_growth.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <stdexcept>

namespace litgs::host {
namespace {

// A budget counts as filled at this share: MCMC's growth multiplies the model by 1 + mcmc_growth per
// refinement up to the budget, so a filled model sits at it exactly.
constexpr double kFilled = 0.98;

std::string db(double v) {
  char buf[32];
  std::snprintf(buf, sizeof buf, "%.3f dB", v);
  return buf;
}

}  // namespace

void BudgetGrowthOptions::check() const {
  auto bad = [](const std::string& what) { throw std::invalid_argument("BudgetGrowthOptions." + what); };
  if (start == 0) bad("start must be positive");
  if (!(factor > 1) || !std::isfinite(factor)) bad("factor must be above 1");
  if (phase_refinements == 0) bad("phase_refinements must be positive");
  if (validation_every < 2) bad("validation_every must be at least 2");
  if (!(min_gain_db >= 0) || !std::isfinite(min_gain_db)) bad("min_gain_db must be finite and >= 0");
  if (!(noise_multiple >= 0) || !std::isfinite(noise_multiple)) bad("noise_multiple must be finite and >= 0");
  if (!(min_transfer >= 0) || !std::isfinite(min_transfer)) bad("min_transfer must be finite and >= 0");
  if (!(until_fraction > 0 && until_fraction <= 1)) bad("until_fraction must be in (0, 1]");
}

BudgetGrowth::BudgetGrowth(const BudgetGrowthOptions& o, uint32_t initial_gaussians, uint32_t ceiling,
                           size_t validation_views)
    : options_(o), ceiling_(ceiling) {
  o.check();
  budget_ = std::min(std::max(o.start, initial_gaussians), ceiling);
  if (validation_views < 2)
    stop_reason_ = std::to_string(validation_views) +
                   " validation view(s) cannot measure the noise of a gain: the budget stays at its start";
  else if (initial_gaussians >= ceiling)
    stop_reason_ = "the initialization already fills the ceiling of " + std::to_string(ceiling);
}

uint32_t BudgetGrowth::decisions_until(const TrainOptions& t) const {
  const auto share = static_cast<uint32_t>(std::floor(options_.until_fraction * t.iterations));
  return std::min(t.refine_until(), share + 1);  // a phase may end at the share's step itself
}

double BudgetGrowth::mcmc_growth_while_growing(double mcmc_growth) const {
  // The step to fill: from the model's size at the last phase's end to the budget (a climb to a rung can be
  // up to factor^1.5); before any phase, one factor. Filled means kFilled of the budget: (1 + g)^phase >=
  // step * kFilled, with a 1 % margin.
  double step = options_.factor;
  if (!phases_.empty() && phases_.back().gaussians > 0)
    step = std::max(1.0, double(budget_) / double(phases_.back().gaussians));
  const double fill = std::pow(step * kFilled, 1.0 / options_.phase_refinements) * 1.01 - 1;
  return std::max(mcmc_growth, fill);
}

bool BudgetGrowth::phase_ends_at(uint32_t step, const TrainOptions& t) const {
  if (!(step > t.densify_from && step < decisions_until(t) && step % t.densify_every == 0)) return false;
  return (step / t.densify_every) % options_.phase_refinements == 0;
}

bool BudgetGrowth::any_phase(const TrainOptions& t) const {
  for (uint32_t step = t.densify_from + 1; step < decisions_until(t); ++step)
    if (phase_ends_at(step, t)) return true;
  return false;
}

bool BudgetGrowth::another_phase_fits(uint32_t step, const TrainOptions& t) const {
  return uint64_t{step} + uint64_t{options_.phase_refinements} * t.densify_every < decisions_until(t);
}

void BudgetGrowth::end_phase(uint32_t step, uint32_t gaussians, const std::vector<double>& views,
                             const std::vector<double>& training, bool another_fits, double wall_s) {
  if (!growing()) return;
  GrowthPhase p;
  p.iteration = step;
  p.budget = budget_;
  p.gaussians = gaussians;
  p.wall_s = wall_s;
  if (gaussians < kFilled * budget_) {
    p.decision = "wait: the model has not filled its budget";
    if (!another_fits)
      stop_reason_ = p.decision = "stop: the densification window ends before the model fills its budget";
    phases_.push_back(p);
    return;
  }
  const auto mean_of = [](const std::vector<double>& v) {
    double sum = 0;
    for (double x : v) sum += x;
    return v.empty() ? NAN : sum / static_cast<double>(v.size());
  };
  p.validation_psnr_db = mean_of(views);
  p.training_psnr_db = mean_of(training);
  const bool first = last_scored_.empty();
  bool gained = first;
  std::string why_not;
  if (!first) {
    if (views.size() != last_scored_.size())
      throw std::logic_error("BudgetGrowth: the validation views changed between phases");
    const size_t n = views.size();
    double mean = 0, sq = 0;
    for (size_t i = 0; i < n; ++i) mean += (views[i] - last_scored_[i]) / static_cast<double>(n);
    for (size_t i = 0; i < n; ++i)
      sq += (views[i] - last_scored_[i] - mean) * (views[i] - last_scored_[i] - mean);
    p.gain_db = mean;
    p.gain_se_db = std::sqrt(sq / static_cast<double>(n - 1) / static_cast<double>(n));
    p.training_gain_db = mean_of(training) - mean_of(last_training_);
    char k[32];
    std::snprintf(k, sizeof k, "%g", options_.noise_multiple);
    if (!(mean > std::max(options_.min_gain_db, options_.noise_multiple * p.gain_se_db))) {
      why_not = "validation gained " + db(mean) + " (standard error " + db(p.gain_se_db) +
                "), not above max(" + db(options_.min_gain_db) + ", " + k + " standard errors)";
    } else if (mean < options_.min_transfer * p.training_gain_db) {
      std::snprintf(k, sizeof k, "%g", options_.min_transfer);
      why_not = "validation gained " + db(mean) + ", less than " + k + " x the training views' " +
                db(p.training_gain_db) + ": the larger model fits the views it trains on";
    }
    gained = why_not.empty();
  }
  const uint32_t previous_budget = last_scored_budget_;
  last_scored_ = views;
  last_training_ = training;
  last_scored_budget_ = budget_;
  const uint64_t next = next_budget();
  if (!gained) {
    p.decision = "stop: " + why_not;
    if (options_.roll_back && previous_budget > 0 && previous_budget < budget_) {
      p.decision +=
          "; back to the budget of " + std::to_string(previous_budget) + ", its most opaque Gaussians kept";
      budget_ = previous_budget;
    }
  } else if (next > ceiling_) {
    p.decision = "stop: the next budget, " + std::to_string(next) + ", is above the ceiling of " +
                 std::to_string(ceiling_);
  } else if (!another_fits) {
    // The last judgement: one more doubling, unjudged, when the next one's gain, extrapolated from the last
    // two (a doubling gains less than the one before, by their ratio), would still pay.
    const double next_gain = extrapolated_gain(p.gain_db);
    if (options_.last_doubling && std::isfinite(next_gain) && next_gain > options_.min_gain_db) {
      p.decision = "stop: the decisions' window ends; one more doubling, to " + std::to_string(next) +
                   ", whose gain extrapolates to " + db(next_gain);
      budget_ = static_cast<uint32_t>(next);
    } else {
      p.decision = "stop: the decisions' window ends before a larger budget could fill";
    }
  } else {
    p.decision = std::string(first ? "grow: first score" : "grow: validation gained " + db(p.gain_db)) +
                 "; budget " + std::to_string(next);
    budget_ = static_cast<uint32_t>(next);
  }
  if (p.decision.rfind("stop", 0) == 0) stop_reason_ = p.decision;
  phases_.push_back(p);
}

uint64_t BudgetGrowth::next_budget() const {
  // At least sqrt(factor) above the current size: a phase spent on a small step (15.7k to 20k) is one of
  // the few the decisions' window holds.
  double rung = options_.start;
  while (rung < budget_ * std::sqrt(options_.factor)) rung = std::ceil(rung * options_.factor);
  return static_cast<uint64_t>(rung);
}

double BudgetGrowth::extrapolated_gain(double last_gain) const {
  if (!(last_gain > 0)) return NAN;
  double before = NAN;  // the gain of the scored phase before the last
  for (auto it = phases_.rbegin(); it != phases_.rend(); ++it)
    if (std::isfinite(it->gain_db)) {
      before = it->gain_db;
      break;
    }
  const double ratio = before > last_gain ? last_gain / before : 0.5;
  return last_gain * ratio;
}

void BudgetGrowth::stop(const std::string& reason) {
  if (growing()) stop_reason_ = "stop: " + reason;
}

nlohmann::json BudgetGrowth::to_json() const {
  nlohmann::json phases = nlohmann::json::array();
  for (const GrowthPhase& p : phases_)
    phases.push_back({{"iteration", p.iteration},
                      {"budget", p.budget},
                      {"gaussians", p.gaussians},
                      {"validation_psnr_db", p.validation_psnr_db},
                      {"gain_db", p.gain_db},
                      {"gain_se_db", p.gain_se_db},
                      {"training_psnr_db", p.training_psnr_db},
                      {"training_gain_db", p.training_gain_db},
                      {"wall_s", p.wall_s},
                      {"decision", p.decision}});
  return {{"budget", budget_},
          {"ceiling", ceiling_},
          {"stop_reason", stop_reason_},
          {"phases", phases},
          {"last_scored_budget", last_scored_budget_},
          {"last_scored_view_psnr_db", last_scored_},
          {"last_scored_training_psnr_db", last_training_}};
}

BudgetGrowth BudgetGrowth::from_json(const BudgetGrowthOptions& options, const nlohmann::json& j) {
  BudgetGrowth g(options, 0, j.at("ceiling").get<uint32_t>(), 2);
  g.budget_ = j.at("budget").get<uint32_t>();
  g.stop_reason_ = j.at("stop_reason").get<std::string>();
  const auto number = [](const nlohmann::json& v) { return v.is_null() ? NAN : v.get<double>(); };
  for (const auto& p : j.at("phases"))
    g.phases_.push_back({p.at("iteration").get<uint32_t>(), p.at("budget").get<uint32_t>(),
                         p.at("gaussians").get<uint32_t>(), number(p.at("validation_psnr_db")),
                         number(p.at("gain_db")), number(p.at("gain_se_db")),
                         number(p.at("training_psnr_db")), number(p.at("training_gain_db")),
                         p.at("wall_s").get<double>(), p.at("decision").get<std::string>()});
  g.last_scored_budget_ = j.value("last_scored_budget", 0u);  // absent before roll-backs: none
  g.last_scored_ = j.at("last_scored_view_psnr_db").get<std::vector<double>>();
  g.last_training_ = j.at("last_scored_training_psnr_db").get<std::vector<double>>();
  return g;
}

std::vector<uint32_t> growth_training_probe_views(const std::vector<uint32_t>& train_views, uint32_t every) {
  std::vector<uint32_t> out;
  for (size_t j = every / 2 + 1; j < train_views.size(); j += every) out.push_back(train_views[j]);
  return out;
}

std::vector<uint32_t> growth_validation_views(const std::vector<uint32_t>& train_views, uint32_t every) {
  std::vector<uint32_t> out;
  for (size_t j = every / 2; j < train_views.size(); j += every) out.push_back(train_views[j]);
  return out;
}

}  // namespace litgs::host
