// The budget search's rule and its validation split (host/train/budget_search.h), on scripted scores.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <map>
#include <stdexcept>

#include "host/train/budget_search.h"

namespace litgs::host {
namespace {

// A train_at that scores each budget from a table, fills it (as MCMC does when its growth reaches the
// budget) and records what ran.
struct Scripted {
  std::map<uint32_t, double> psnr;
  std::vector<uint32_t> ran;
  std::map<uint32_t, std::vector<double>> views;  // per-view PSNRs where given (psnr is then their mean)
  BudgetTrial operator()(uint32_t budget) {
    ran.push_back(budget);
    BudgetTrial t;
    if (views.count(budget) > 0) {
      t.view_psnr_db = views.at(budget);
      for (double v : t.view_psnr_db) t.psnr_db += v / static_cast<double>(t.view_psnr_db.size());
    } else {
      t.psnr_db = psnr.at(budget);
    }
    t.gaussians = budget;
    return t;
  }
};

// Four validation views; each budget's PSNR per view is the 80k one's less `shortfall` plus `wobble` per
// view.
std::vector<double> views_below_80k(double shortfall, std::vector<double> wobble) {
  const std::vector<double> at_80k = {23.0, 22.0, 24.0, 21.0};
  for (size_t v = 0; v < wobble.size(); ++v) wobble[v] = at_80k[v] - shortfall + wobble[v];
  return wobble;
}

// The tests of the plateau, patience and parsimony mechanics use a 0.1 dB threshold, whatever the default.
BudgetSearchOptions tenth_db() {
  BudgetSearchOptions o;
  o.min_gain_db = 0.1;
  return o;
}

TEST(BudgetSearch, KeepsTheLastBudgetThatGainedAndStopsAfterTwoThatDidNot) {
  Scripted s{{{5000, 21.5}, {10000, 21.8}, {20000, 22.0}, {40000, 22.05}, {80000, 22.08}, {160000, 23.0}},
             {}};
  const BudgetSearchResult r = search_budget(std::ref(s), 3988, tenth_db());
  EXPECT_EQ(r.chosen, 20000u);  // 40k and 80k gained under 0.1 dB: stop there; 160k is never tried
  EXPECT_EQ(s.ran, (std::vector<uint32_t>{5000, 10000, 20000, 40000, 80000}));
  ASSERT_EQ(r.trials.size(), 5u);
  EXPECT_EQ(r.trials[3].budget, 40000u);
  EXPECT_DOUBLE_EQ(r.trials[3].psnr_db, 22.05);
}

TEST(BudgetSearch, LooksOneBudgetPastAPlateau) {
  // The facade's shape: nothing gained at 20k, then much at 40k and 80k.
  Scripted s{{{5000, 33.85},
              {10000, 35.0},
              {20000, 34.86},
              {40000, 35.5},
              {80000, 36.0},
              {160000, 36.05},
              {320000, 35.9}},
             {}};
  EXPECT_EQ(search_budget(std::ref(s), 0, tenth_db()).chosen, 80000u);
  EXPECT_EQ(s.ran.back(), 320000u);
  BudgetSearchOptions impatient = tenth_db();
  impatient.patience = 0;
  Scripted t{s.psnr, {}};
  EXPECT_EQ(search_budget(std::ref(t), 0, impatient).chosen, 10000u);
}

TEST(BudgetSearch, ABudgetTheTrainingDidNotFillEndsTheSearch) {
  // DUNR's shape: growth from 3,988 points reaches 156,975 Gaussians in 2,000 iterations, so 160k is not
  // filled and 320k would train the same model.
  std::vector<uint32_t> ran;
  const auto train_at = [&](uint32_t budget) {
    ran.push_back(budget);
    BudgetTrial t;
    t.gaussians = std::min<uint32_t>(budget, 156975);
    t.psnr_db = budget <= 80000 ? 20.0 + budget / 20000.0 : 20.0;  // gains up to 80k, then falls
    return t;
  };
  EXPECT_EQ(search_budget(train_at, 3988).chosen, 80000u);
  EXPECT_EQ(ran, (std::vector<uint32_t>{5000, 10000, 20000, 40000, 80000, 160000}));  // not 320k
  // Filled budgets do not end it: the plateau rule does.
  Scripted s{{{5000, 21.0}, {10000, 21.5}, {20000, 21.5}, {40000, 21.5}}, {}};
  EXPECT_EQ(search_budget(std::ref(s), 0).chosen, 10000u);
  EXPECT_EQ(s.ran.size(), 4u);
}

TEST(BudgetSearch, BudgetsTheInitializationFilledDoNotCountAsAPlateau) {
  // The facade through `run`: seeded from 21k LiDAR map points, 5k, 10k and 20k start full and score flat;
  // the budgets past the seeding then gain.
  const std::map<uint32_t, double> psnr = {{5000, 33.06}, {10000, 32.92},  {20000, 33.02}, {40000, 33.6},
                                           {80000, 34.2}, {160000, 34.25}, {320000, 34.0}};
  std::vector<uint32_t> ran;
  const auto train_at = [&](uint32_t budget) {
    ran.push_back(budget);
    BudgetTrial t;
    t.psnr_db = psnr.at(budget);
    t.gaussians = budget;
    t.initial_gaussians = std::min<uint32_t>(budget, 21297);
    return t;
  };
  EXPECT_EQ(search_budget(train_at, 5000, tenth_db()).chosen, 80000u);
  EXPECT_EQ(ran, (std::vector<uint32_t>{5000, 10000, 20000, 40000, 80000, 160000, 320000}));
  // The same scores from a seeding that never fills a budget: the plateau at 10k and 20k ends the search.
  Scripted s{psnr, {}};
  EXPECT_EQ(search_budget(std::ref(s), 5000, tenth_db()).chosen, 5000u);
  EXPECT_EQ(s.ran.back(), 20000u);
}

TEST(BudgetSearch, AFallStopsTheSearchAtTheBudgetBeforeIt) {
  Scripted s{{{5000, 21.5},
              {10000, 21.7},
              {20000, 22.0},
              {40000, 22.2},
              {80000, 22.4},
              {160000, 21.7},
              {320000, 21.2}},
             {}};
  EXPECT_EQ(search_budget(std::ref(s), 0).chosen, 80000u);
  EXPECT_EQ(s.ran.back(), 320000u);
}

TEST(BudgetSearch, WithoutAMinimumGainAnyRiseOverTheBestCounts) {
  // The facade's deterministic search at seed 0 (docs/budget.md): 320k rose 0.04 dB over 160k.
  const std::map<uint32_t, double> psnr = {{5000, 33.46},   {10000, 34.40},  {20000, 34.32},
                                           {40000, 35.40},  {80000, 36.13},  {160000, 36.83},
                                           {320000, 36.87}, {640000, 36.47}, {1280000, 36.5}};
  Scripted a{psnr, {}};
  EXPECT_EQ(search_budget(std::ref(a), 0, tenth_db()).chosen, 160000u);
  EXPECT_EQ(a.ran.back(), 640000u);
  BudgetSearchOptions any;
  any.min_gain_db = 0.0;
  Scripted b{psnr, {}};
  EXPECT_EQ(search_budget(std::ref(b), 0, any).chosen, 320000u);
  EXPECT_EQ(b.ran.back(), 1280000u);  // 640k and 1.28M below 320k: two budgets in a row without a rise
  // A tie is no rise: it counts towards the plateau.
  Scripted flat{{{5000, 21.0}, {10000, 21.5}, {20000, 21.5}, {40000, 21.5}}, {}};
  EXPECT_EQ(search_budget(std::ref(flat), 0, any).chosen, 10000u);
  EXPECT_EQ(flat.ran.back(), 40000u);
}

TEST(BudgetSearch, StartsAtTheInitializationsSizeAndStopsAtTheCap) {
  Scripted s{{{30000, 30.0}, {60000, 31.0}, {100000, 32.0}}, {}};
  BudgetSearchOptions o;
  o.max_budget = 100000;
  EXPECT_EQ(search_budget(std::ref(s), 30000, o).chosen, 100000u);
  EXPECT_EQ(s.ran, (std::vector<uint32_t>{30000, 60000, 100000}));  // the cap ends it while still gaining
}

TEST(BudgetSearch, ANonFiniteScoreIsNeverAGain) {
  Scripted s{{{5000, 20.0}, {10000, NAN}, {20000, NAN}}, {}};
  EXPECT_EQ(search_budget(std::ref(s), 0).chosen, 5000u);
  Scripted first_nan{{{5000, NAN}, {10000, NAN}}, {}};
  const BudgetSearchResult r = search_budget(std::ref(first_nan), 0);
  EXPECT_EQ(r.chosen, 5000u);
  EXPECT_EQ(r.trials.size(), 2u);
}

TEST(BudgetSearch, ABudgetTheDeviceCannotHoldEndsTheSearchAtTheOneBefore) {
  std::vector<uint32_t> ran;
  const auto train_at = [&](uint32_t budget) {
    ran.push_back(budget);
    if (budget > 20000) throw std::length_error("out of memory allocating buffer 'gaussians: sh'");
    BudgetTrial t;
    t.psnr_db = budget / 1000.0;
    return t;
  };
  const BudgetSearchResult r = search_budget(train_at, 0);
  EXPECT_EQ(r.chosen, 20000u);
  EXPECT_EQ(ran, (std::vector<uint32_t>{5000, 10000, 20000, 40000}));
  ASSERT_EQ(r.trials.size(), 4u);
  EXPECT_TRUE(std::isnan(r.trials.back().psnr_db));
  EXPECT_NE(r.trials.back().failure.find("out of memory"), std::string::npos);
  // At the first budget there is nothing to fall back on: the error is the caller's.
  const auto never = [](uint32_t) -> BudgetTrial { throw std::length_error("too large"); };
  EXPECT_THROW(search_budget(never, 0), std::length_error);
  // Other errors are not a budget's size: they pass through.
  const auto broken = [](uint32_t budget) -> BudgetTrial {
    if (budget > 5000) throw std::runtime_error("disk full");
    return BudgetTrial{0, 20.0};
  };
  EXPECT_THROW(search_budget(broken, 0), std::runtime_error);
}

TEST(BudgetSearch, WithParsimonyKeepsTheSmallestBudgetWithinOneStandardErrorOfTheLastThatGained) {
  // 80k gains 0.15 dB over 40k on average, but the views disagree (shortfalls -0.25..0.65): within noise.
  // 20k lacks 1 dB on every view: a real loss. 160k gains nothing and 320k falls: 80k is the reference.
  Scripted s;
  s.views = {{5000, views_below_80k(2.0, {0, 0.1, -0.1, 0})},
             {10000, views_below_80k(1.5, {0, 0.1, -0.1, 0})},
             {20000, views_below_80k(1.0, {0.05, -0.05, 0.1, -0.1})},
             {40000, views_below_80k(0.15, {0.4, -0.5, 0.3, -0.2})},
             {80000, views_below_80k(0, {0, 0, 0, 0})},
             {160000, views_below_80k(0, {0.02, -0.02, 0.01, 0})},
             {320000, views_below_80k(0.5, {0, 0, 0, 0})}};
  BudgetSearchOptions one_se = tenth_db();
  one_se.parsimony_se = 1;
  Scripted by_default = s;
  const BudgetSearchResult r = search_budget(std::ref(s), 0, one_se);
  EXPECT_EQ(r.reference, 80000u);
  EXPECT_EQ(r.chosen, 40000u);
  ASSERT_EQ(r.trials.size(), 7u);
  // 40k's per-view shortfalls: -0.25, 0.65, -0.15, 0.35; mean 0.15, sample sd sqrt(0.54 / 3), SE sd / 2.
  EXPECT_NEAR(r.trials[3].shortfall_db, 0.15, 1e-12);
  EXPECT_NEAR(r.trials[3].shortfall_se_db, std::sqrt(0.54 / 3.0) / 2.0, 1e-12);
  EXPECT_NEAR(r.trials[2].shortfall_db, 1.0, 1e-12);
  EXPECT_DOUBLE_EQ(r.trials[4].shortfall_db, 0.0);    // the reference against itself
  EXPECT_NEAR(r.trials[6].shortfall_db, 0.5, 1e-12);  // larger budgets are measured too, never chosen

  // Without parsimony (0 standard errors, the default) the last budget that gained is kept, and the
  // shortfalls are still recorded.
  const BudgetSearchResult d = search_budget(std::ref(by_default), 0, tenth_db());
  EXPECT_EQ(d.chosen, 80000u);
  EXPECT_EQ(d.reference, 80000u);
  EXPECT_NEAR(d.trials[3].shortfall_db, 0.15, 1e-12);
}

TEST(BudgetSearch, AGainEveryViewAgreesOnIsKept) {
  // 40k lacks 0.15 dB on every view (+-0.01): small, but not noise.
  Scripted s;
  s.views = {
      {5000, views_below_80k(2.0, {0, 0, 0, 0})},  {10000, views_below_80k(1.0, {0, 0, 0, 0})},
      {20000, views_below_80k(0.5, {0, 0, 0, 0})}, {40000, views_below_80k(0.15, {0.01, -0.01, 0.01, -0.01})},
      {80000, views_below_80k(0, {0, 0, 0, 0})},   {160000, views_below_80k(0.1, {0, 0, 0, 0})},
      {320000, views_below_80k(0.3, {0, 0, 0, 0})}};
  BudgetSearchOptions one_se = tenth_db();
  one_se.parsimony_se = 1;
  EXPECT_EQ(search_budget(std::ref(s), 0, one_se).chosen, 80000u);
}

TEST(BudgetSearch, TrialsWithoutPairedViewsAreNeverChosenOverTheReference) {
  std::vector<BudgetTrial> trials(3);
  trials[0].view_psnr_db = {20.0, 21.0};              // two views
  trials[1].view_psnr_db = {20.0, 21.0, 22.0};        // three: no pairs with the reference
  trials[2].view_psnr_db = {20.0, 21.0, 22.0, 23.0};  // the reference
  EXPECT_EQ(choose_within_standard_errors(trials, 2, 1.0), 2u);
  EXPECT_TRUE(std::isnan(trials[0].shortfall_db));
  trials[1].view_psnr_db = {NAN, 21.0, 22.0, 23.0};  // a non-finite view
  EXPECT_EQ(choose_within_standard_errors(trials, 2, 1.0), 2u);
  trials[1].view_psnr_db = {20.0, 21.0, 22.0, 23.0};  // identical scores: within any error
  EXPECT_EQ(choose_within_standard_errors(trials, 2, 1.0), 1u);
  trials[1].failure = "out of memory";
  EXPECT_EQ(choose_within_standard_errors(trials, 2, 1.0), 2u);
  std::vector<BudgetTrial> one_view(2);
  one_view[0].view_psnr_db = {19.0};
  one_view[1].view_psnr_db = {20.0};
  EXPECT_EQ(choose_within_standard_errors(one_view, 1, 1.0), 1u);  // no standard error from one view
}

TEST(BudgetSearch, BadOptionsAreRefusedByName) {
  Scripted s{{{5000, 1.0}}, {}};
  BudgetSearchOptions o;
  o.factor = 1.0;
  EXPECT_THROW(search_budget(std::ref(s), 0, o), std::invalid_argument);
  o = {};
  o.validation_every = 1;
  EXPECT_THROW(search_budget(std::ref(s), 0, o), std::invalid_argument);
  o = {};
  o.folds = 0;
  EXPECT_THROW(search_budget(std::ref(s), 0, o), std::invalid_argument);
  o = {};
  o.min_gain_db = NAN;
  EXPECT_THROW(search_budget(std::ref(s), 0, o), std::invalid_argument);
  o = {};
  o.parsimony_se = -1;
  EXPECT_THROW(search_budget(std::ref(s), 0, o), std::invalid_argument);
  EXPECT_TRUE(s.ran.empty());
}

// `frames` views named by their index, every 8th held out as the scene's test views.
TrainingData views_with_every_8th_held_out(int frames) {
  TrainingData d;
  for (int i = 0; i < frames; ++i) {
    TrainingView v;
    v.name = std::to_string(i);
    v.heldout = i % 8 == 0;
    d.views.push_back(v);
  }
  return d;
}

TEST(BudgetSearch, TheValidationSplitDropsTheTestViewsAndHoldsOutEveryKthTrainingView) {
  const TrainingData d = views_with_every_8th_held_out(45);  // 6 test views
  const TrainingData s = validation_split(d, 8);
  ASSERT_EQ(s.views.size(), 39u);
  size_t validation = 0;
  for (size_t i = 0; i < s.views.size(); ++i) {
    EXPECT_NE(std::stoi(s.views[i].name) % 8, 0) << "a test view went into the search";
    validation += s.views[i].heldout;
  }
  EXPECT_EQ(validation, 5u);  // views 4, 12, 20, 28, 36 of the 39
  EXPECT_TRUE(s.views[4].heldout);
  EXPECT_FALSE(s.views[0].heldout);

  TrainingData few;
  few.views.resize(3);
  const TrainingData f = validation_split(few, 8);
  EXPECT_EQ(f.views[1].heldout + f.views[0].heldout + f.views[2].heldout, 1);  // always one
  few.views.resize(1);
  EXPECT_THROW(validation_split(few, 8), std::invalid_argument);
}

TEST(BudgetSearch, TheTwoFoldsValidateOnDisjointViewsHalfAStrideApart) {
  const TrainingData d = views_with_every_8th_held_out(40);  // 5 test views
  const TrainingData f0 = validation_split(d, 8, 0, 2), f1 = validation_split(d, 8, 1, 2);
  ASSERT_EQ(f0.views.size(), 35u);
  ASSERT_EQ(f1.views.size(), 35u);
  std::vector<size_t> v0, v1;
  for (size_t i = 0; i < 35; ++i) {
    EXPECT_EQ(f0.views[i].name, f1.views[i].name);  // the same views, split differently
    if (f0.views[i].heldout) v0.push_back(i);
    if (f1.views[i].heldout) v1.push_back(i);
    EXPECT_FALSE(f0.views[i].heldout && f1.views[i].heldout) << "view " << i << " validates in both folds";
  }
  EXPECT_EQ(v0, (std::vector<size_t>{4, 12, 20, 28}));  // fold 0 is the one-fold split
  EXPECT_EQ(v1, (std::vector<size_t>{0, 8, 16, 24, 32}));
  EXPECT_EQ(validation_split(d, 8).views[4].heldout, true);

  TrainingData few;
  few.views.resize(3);
  const TrainingData a = validation_split(few, 8, 0, 2), b = validation_split(few, 8, 1, 2);
  for (size_t i = 0; i < 3; ++i) EXPECT_FALSE(a.views[i].heldout && b.views[i].heldout);
  EXPECT_THROW(validation_split(d, 8, 2, 2), std::invalid_argument);  // no fold 2 of 2
  EXPECT_THROW(validation_split(d, 8, 0, 9), std::invalid_argument);  // more folds than offsets
}

TEST(BudgetSearch, EightFoldsValidateEveryTrainingViewExactlyOnce) {
  const TrainingData d = views_with_every_8th_held_out(40);  // 35 training views
  std::vector<int> validated(35, 0);
  for (uint32_t fold = 0; fold < 8; ++fold) {
    const TrainingData f = validation_split(d, 8, fold, 8);
    ASSERT_EQ(f.views.size(), 35u);
    for (size_t i = 0; i < 35; ++i) validated[i] += f.views[i].heldout;
  }
  EXPECT_EQ(validated, std::vector<int>(35, 1));
}

}  // namespace
}  // namespace litgs::host
