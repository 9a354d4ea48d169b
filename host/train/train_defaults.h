// The training defaults that `train` and `run` share, so that a user who calls `train` directly gets what
// `run` gives: MCMC with the budget grown inside one training while held-back views gain (docs/budget.md: as
// good as the best fixed budget within about the time of one training, where the search of one training per
// budget cost 20-95 of them on a CPU device; MCMC ahead of capped ADC on the real DUNR facade,
// docs/results.md). TrainOptions, train's CLI and run.yaml's train section all start from these; the figures
// behind them are in docs/results.md, not here.
#pragma once

#include <cstdint>

namespace litgs::host::train_defaults {

inline constexpr uint32_t kIterations = 2000;
inline constexpr const char* kStrategy = "mcmc";
// --max-gaussians: a count, auto, search or grow (host/train/budget_flag.h).
inline constexpr const char* kMaxGaussians = "grow";
inline constexpr double kMcmcGrowth = 0.3;       // rows added per refinement, as a fraction of the model
inline constexpr double kLambdaGeo = 0.6;        // L = (1 - lambda_geo) L_pho + lambda_geo L_geo
inline constexpr uint32_t kGrowthStart = 10000;  // grow's first budget (BudgetGrowthOptions::start)

}  // namespace litgs::host::train_defaults
