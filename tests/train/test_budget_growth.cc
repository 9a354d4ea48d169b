// The rule of `--max-gaussians grow` (host/train/budget_growth.h) on made-up scores: when it grows, waits and
// stops, and the named hard cases: validation noise larger than the gain, a larger model that fits only the
// views it trains on, a budget above what the device holds, a scene whose validation set is one view, an
// initialization that already fills the ceiling or covers the scene (the doubling rolled back); and a resume
// from its JSON state deciding as the uninterrupted run.
#include <gtest/gtest.h>

#include <cmath>
#include <vector>

#include "host/train/budget_growth.h"

namespace litgs::host {
namespace {

std::vector<double> shifted(const std::vector<double>& v, double by) {
  std::vector<double> out = v;
  for (double& x : out) x += by;
  return out;
}

const std::vector<double> kViews = {30.0, 31.2, 29.5, 32.4, 30.8};

// A doubling from a filled budget: MCMC's default growth of 0.3 per refinement already fills it.
double g_after_doubling() {
  BudgetGrowth g(BudgetGrowthOptions{}, 20000, 4000000, kViews.size());
  g.end_phase(600, 20000, kViews, kViews, true, 1);
  return g.mcmc_growth_while_growing(0.3);
}
const std::vector<double> kNoise = {-0.9, 1.1, -0.7, 0.8, 0.0};  // mean 0.06, spread ~0.9 dB

TEST(BudgetGrowth, PhasesEndEveryFewRefinementsInsideTheWindow) {
  TrainOptions t;
  t.iterations = 2000;
  t.densify_from = 500;
  t.densify_every = 100;
  BudgetGrowthOptions o;
  o.phase_refinements = 3;
  o.until_fraction = 1.0;
  const BudgetGrowth whole(o, 1000, 100000, 4);
  std::vector<uint32_t> ends;
  for (uint32_t step = 1; step <= t.iterations; ++step)
    if (whole.phase_ends_at(step, t)) ends.push_back(step);
  EXPECT_EQ(ends, (std::vector<uint32_t>{600, 900, 1200, 1500, 1800}));
  EXPECT_TRUE(whole.another_phase_fits(1500, t));
  EXPECT_FALSE(whole.another_phase_fits(1800, t));  // 2100 is past the window's end at 2000
  o.until_fraction = 0.6;  // decisions end by iteration 1200; the rest trains at the final size
  const BudgetGrowth early(o, 1000, 100000, 4);
  ends.clear();
  for (uint32_t step = 1; step <= t.iterations; ++step)
    if (early.phase_ends_at(step, t)) ends.push_back(step);
  EXPECT_EQ(ends, (std::vector<uint32_t>{600, 900, 1200}));
  EXPECT_TRUE(early.another_phase_fits(900, t));
  EXPECT_FALSE(early.another_phase_fits(1200, t));
}

TEST(BudgetGrowth, GrowsWhileValidationGainsAndStopsWhenItNoLongerDoes) {
  BudgetGrowthOptions o;
  BudgetGrowth g(o, 20000, 4000000, kViews.size());
  EXPECT_EQ(g.budget(), 20000u);  // the initialization's size, above the start of 10000
  g.end_phase(600, 20000, kViews, shifted(kViews, 2), true, 1);
  EXPECT_EQ(g.budget(), 40000u);  // the first score is a baseline
  g.end_phase(900, 40000, shifted(kViews, 0.8), shifted(kViews, 2.8), true, 2);
  EXPECT_EQ(g.budget(), 80000u);
  EXPECT_TRUE(g.growing());
  g.end_phase(1200, 80000, shifted(kViews, 0.82), shifted(kViews, 2.85), true, 3);  // +0.02 dB: no gain
  EXPECT_FALSE(g.growing());
  EXPECT_EQ(g.budget(), 40000u) << "the doubling that did not pay is rolled back";
  EXPECT_NE(g.stop_reason().find("validation gained 0.020 dB"), std::string::npos) << g.stop_reason();
  EXPECT_NE(g.stop_reason().find("back to the budget of 40000"), std::string::npos) << g.stop_reason();
  g.end_phase(1500, 80000, shifted(kViews, 5), shifted(kViews, 5), true, 4);  // ignored once stopped
  EXPECT_EQ(g.phases().size(), 3u);
}

// By default the mean decides and the standard error is recorded beside it: a doubling is cheap to undo
// (roll-back), and on real frames five validation views have a gain's standard error as large as a doubling's
// gain (docs/budget.md), so that asking for significance stops every scene at its start.
// --growth-noise-multiple asks for it.
TEST(BudgetGrowth, ValidationNoiseLargerThanTheGainLetsTheMeanDecideUnlessSignificanceIsAsked) {
  std::vector<double> noisy = kViews;
  for (size_t i = 0; i < noisy.size(); ++i) noisy[i] += 0.3 + kNoise[i];  // mean +0.36, standard error ~0.39
  BudgetGrowthOptions o;
  BudgetGrowth by_mean(o, 10000, 4000000, kViews.size());
  by_mean.end_phase(600, 10000, kViews, kViews, true, 1);
  by_mean.end_phase(900, 20000, noisy, shifted(kViews, 0.3), true, 2);
  EXPECT_TRUE(by_mean.growing());
  EXPECT_EQ(by_mean.budget(), 40000u);
  EXPECT_GT(by_mean.phases().back().gain_se_db, by_mean.phases().back().gain_db);  // recorded, not hidden
  std::vector<double> losing = kViews;
  for (size_t i = 0; i < losing.size(); ++i) losing[i] += 0.3 + kNoise[i] - 0.4;  // mean -0.04
  by_mean.end_phase(1200, 40000, losing, shifted(kViews, 0.5), true, 3);
  EXPECT_FALSE(by_mean.growing());
  EXPECT_EQ(by_mean.budget(), 20000u);

  o.noise_multiple = 2;
  BudgetGrowth significant(o, 10000, 4000000, kViews.size());
  significant.end_phase(600, 10000, kViews, kViews, true, 1);
  significant.end_phase(900, 20000, noisy, shifted(kViews, 0.3), true, 2);
  EXPECT_FALSE(significant.growing());
  EXPECT_EQ(significant.budget(), 10000u);
  EXPECT_NE(significant.stop_reason().find("2 standard errors"), std::string::npos)
      << significant.stop_reason();
}

TEST(BudgetGrowth, ALargerModelThatFitsOnlyTheViewsItTrainsOnStopsWhenTransferIsAsked) {
  BudgetGrowthOptions o;
  o.min_transfer = 0.5;
  BudgetGrowth g(o, 10000, 4000000, kViews.size());
  g.end_phase(600, 10000, kViews, kViews, true, 1);
  g.end_phase(900, 20000, shifted(kViews, 0.3), shifted(kViews, 1.0), true, 2);  // 0.3 < 0.5 x 1.0
  EXPECT_FALSE(g.growing());
  EXPECT_NE(g.stop_reason().find("fits the views it trains on"), std::string::npos) << g.stop_reason();
}

TEST(BudgetGrowth, AnInitializationThatAlreadyCoversTheSceneStopsAtItsFirstDoublingAndReturnsToIt) {
  BudgetGrowthOptions o;
  BudgetGrowth g(o, 20000, 4000000, kViews.size());
  g.end_phase(600, 20000, kViews, shifted(kViews, 0.5), true, 1);
  EXPECT_EQ(g.budget(), 40000u);  // the first score only sets the baseline
  g.end_phase(900, 40000, shifted(kViews, -0.01), shifted(kViews, 0.4), true, 2);
  EXPECT_FALSE(g.growing());
  EXPECT_EQ(g.budget(), 20000u);
}

TEST(BudgetGrowth, WithoutRollBackTheLastDoublingStays) {
  BudgetGrowthOptions o;
  o.roll_back = false;
  BudgetGrowth g(o, 20000, 4000000, kViews.size());
  g.end_phase(600, 20000, kViews, kViews, true, 1);
  g.end_phase(900, 40000, shifted(kViews, -0.01), shifted(kViews, 0.4), true, 2);
  EXPECT_FALSE(g.growing());
  EXPECT_EQ(g.budget(), 40000u);
  EXPECT_EQ(g.stop_reason().find("back to"), std::string::npos) << g.stop_reason();
}

TEST(BudgetGrowth, TheLastJudgementTakesOneMoreDoublingWhenTheExtrapolatedGainPays) {
  BudgetGrowthOptions o;
  BudgetGrowth g(o, 20000, 4000000, kViews.size());
  g.end_phase(600, 20000, kViews, kViews, true, 1);
  g.end_phase(900, 40000, shifted(kViews, 2.0), kViews, true, 2);
  g.end_phase(1200, 80000, shifted(kViews, 2.8), kViews, false, 3);  // +0.8 after +2.0: next ~ +0.32
  EXPECT_FALSE(g.growing());
  EXPECT_EQ(g.budget(), 160000u);
  EXPECT_NE(g.stop_reason().find("gain extrapolates to 0.320 dB"), std::string::npos) << g.stop_reason();

  BudgetGrowth flat(o, 20000, 4000000, kViews.size());
  flat.end_phase(600, 20000, kViews, kViews, true, 1);
  flat.end_phase(900, 40000, shifted(kViews, 0.8), kViews, true, 2);
  flat.end_phase(1200, 80000, shifted(kViews, 0.9), kViews, false, 3);  // +0.1 after +0.8: next ~ +0.0125
  EXPECT_EQ(flat.budget(), 80000u);
  EXPECT_NE(flat.stop_reason().find("window ends before"), std::string::npos) << flat.stop_reason();

  o.last_doubling = false;
  BudgetGrowth off(o, 20000, 4000000, kViews.size());
  off.end_phase(600, 20000, kViews, kViews, true, 1);
  off.end_phase(900, 40000, shifted(kViews, 2.0), kViews, false, 2);
  EXPECT_EQ(off.budget(), 40000u);
}

TEST(BudgetGrowth, AShortTrainingHasNoPhaseAndSaysSo) {
  TrainOptions t;
  t.iterations = 300;  // ci/demo's: the decisions' window ends at 181, before densification starts at 500
  BudgetGrowthOptions o;
  const BudgetGrowth g(o, 20000, 4000000, kViews.size());
  EXPECT_FALSE(g.any_phase(t));
  t.iterations = 2000;
  EXPECT_TRUE(g.any_phase(t));
}

TEST(BudgetGrowth, WaitsUntilTheModelFillsItsBudgetButNotPastTheWindow) {
  BudgetGrowthOptions o;
  BudgetGrowth g(o, 10000, 4000000, kViews.size());
  g.end_phase(600, 10000, kViews, kViews, true, 1);
  g.end_phase(900, 15000, shifted(kViews, 2), shifted(kViews, 2), true, 2);  // 15k of 20k: not judged
  EXPECT_TRUE(g.growing());
  EXPECT_EQ(g.budget(), 20000u);
  EXPECT_TRUE(std::isnan(g.phases().back().validation_psnr_db));
  g.end_phase(1200, 18000, shifted(kViews, 2), shifted(kViews, 2), false, 3);
  EXPECT_FALSE(g.growing());
  EXPECT_NE(g.stop_reason().find("window ends"), std::string::npos);
}

TEST(BudgetGrowth, ABudgetAboveWhatTheDeviceHoldsIsNeverSet) {
  BudgetGrowthOptions o;
  BudgetGrowth g(o, 320000, 699050, kViews.size());  // lavapipe's 128 MiB over 48 floats per Gaussian
  g.end_phase(600, 320000, kViews, kViews, true, 1);
  EXPECT_EQ(g.budget(), 640000u);
  g.end_phase(900, 640000, shifted(kViews, 1), shifted(kViews, 1), true, 2);
  EXPECT_FALSE(g.growing());
  EXPECT_EQ(g.budget(), 640000u);
  EXPECT_NE(g.stop_reason().find("the next budget, 1280000, is above the ceiling of 699050"),
            std::string::npos)
      << g.stop_reason();
}

// Budgets climb the ladder start x 2^k where the fixed budgets are measured: an initialization between two
// rungs (the facade's 20,934 LiDAR points) goes to the next rung, not to twice its own size, unless that rung
// is less than sqrt(2) above it.
TEST(BudgetGrowth, AnInitializationBetweenTwoRungsClimbsToTheNextRung) {
  BudgetGrowthOptions o;
  BudgetGrowth g(o, 20934, 4000000, kViews.size());
  EXPECT_EQ(g.budget(), 20934u);
  g.end_phase(600, 20934, kViews, kViews, true, 1);
  EXPECT_EQ(g.budget(), 40000u);
  g.end_phase(900, 40000, shifted(kViews, 1), kViews, true, 2);
  EXPECT_EQ(g.budget(), 80000u);
  g.end_phase(1200, 80000, shifted(kViews, 1.01), kViews, true, 3);  // no gain: back to the last rung
  EXPECT_EQ(g.budget(), 40000u);
  // Less than sqrt(2) to the next rung (the street's 15,716 LiDAR points, 20k): the rung after it, and MCMC
  // grows fast enough to fill that 2.5x step within the phase's three refinements (0.3 fills a doubling).
  BudgetGrowth close(o, 15716, 4000000, kViews.size());
  close.end_phase(600, 15716, kViews, kViews, true, 1);
  EXPECT_EQ(close.budget(), 40000u);
  const double rate = close.mcmc_growth_while_growing(0.3);
  EXPECT_GT(15716 * std::pow(1 + rate, o.phase_refinements), 0.98 * 40000) << rate;
  EXPECT_LT(rate, 0.4);
  EXPECT_DOUBLE_EQ(g_after_doubling(), 0.3);
  o.start = 5000;
  o.factor = 3;
  BudgetGrowth thirds(o, 20934, 4000000, kViews.size());
  thirds.end_phase(600, 20934, kViews, kViews, true, 1);
  EXPECT_EQ(thirds.budget(), 45000u);  // 5k, 15k, 45k: the first at least sqrt(3) x 20,934
}

TEST(BudgetGrowth, OneValidationViewCannotJudgeAndTheBudgetStaysAtItsStart) {
  BudgetGrowthOptions o;
  const BudgetGrowth g(o, 3000, 4000000, 1);  // an 8-frame scene: 7 training views, 1 validates
  EXPECT_FALSE(g.growing());
  EXPECT_EQ(g.budget(), 10000u);  // the start, above the initialization's size
  EXPECT_NE(g.stop_reason().find("cannot measure the noise"), std::string::npos);
}

TEST(BudgetGrowth, AnInitializationThatFillsTheCeilingDoesNotGrow) {
  BudgetGrowthOptions o;
  const BudgetGrowth g(o, 5000000, 4000000, kViews.size());
  EXPECT_FALSE(g.growing());
  EXPECT_EQ(g.budget(), 4000000u);
}

TEST(BudgetGrowth, ResumedFromItsJsonItDecidesAsTheUninterruptedRun) {
  BudgetGrowthOptions o;
  BudgetGrowth whole(o, 10000, 4000000, kViews.size());
  whole.end_phase(600, 10000, kViews, kViews, true, 1);
  BudgetGrowth resumed = BudgetGrowth::from_json(o, nlohmann::json::parse(whole.to_json().dump()));
  for (BudgetGrowth* g : {&whole, &resumed}) {
    g->end_phase(900, 20000, shifted(kViews, 0.4), shifted(kViews, 0.5), true, 2);
    g->end_phase(1200, 40000, shifted(kViews, 0.42), shifted(kViews, 0.9), true, 3);
  }
  EXPECT_EQ(resumed.to_json().dump(), whole.to_json().dump());  // as text: NaN never equals itself
  EXPECT_FALSE(whole.growing());
  EXPECT_EQ(whole.budget(), 20000u);  // 40k gained 0.02 dB over 20k: rolled back
}

}  // namespace
}  // namespace litgs::host
