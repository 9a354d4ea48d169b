// The options `litgs-engine train` shares with run.yaml's train section (host/option_name.h). Their values
// and defaults live in TrainOptions (train_options.h, train_defaults.h) and RunConfig::Train.
#pragma once

#include "host/option_name.h"

namespace litgs::host::train_option {

inline constexpr OptionName kIterations{"iterations", "--iterations", "Training iterations"};
inline constexpr OptionName kDownscale{"downscale", "--downscale",
                                       "Divide image size and intrinsics by this"};
inline constexpr OptionName kStrategy{
    "strategy", "--strategy",
    "Density control: mcmc (a fixed or grown budget, 3DGS-MCMC; the default, ahead of capped adc on the real "
    "DUNR facade: docs/results.md) or adc (3DGS's densification, capped by --max-gaussians)"};
inline constexpr OptionName kMaxGaussians{
    "max_gaussians", "--max-gaussians",
    "The MCMC budget (adc: the cap): grow (the default: doubled inside one training while every 8th training "
    "view, held back meanwhile, still gains; docs/cli/train.md), a count (40000 for a fixed one), auto "
    "(derived from the surface the training views see: the LiDAR map, else the initialization's points) or "
    "search (one training per doubled budget and fold while their validation PSNR still rises: slower, the "
    "reference grow was measured against; docs/budget.md)"};
inline constexpr OptionName kMcmcGrowth{"mcmc_growth", "--mcmc-growth",
                                        "MCMC: growth per refinement (fraction)"};
inline constexpr OptionName kLambdaGeo{"lambda_geo", "--lambda-geo",
                                       "Weight of the LiDAR point-to-plane loss"};
inline constexpr OptionName kInit{
    "init", "--init",
    "auto (the LiDAR map, else the front end's points in SCENE/sfm/, else random), random, sfm (the front "
    "end's points), or a .ply/.pcd point file (run.yaml also takes refined: refine's points)"};
inline constexpr OptionName kHoldoutEvery{"holdout_every", "--holdout-every",
                                          "Hold out every Nth frame for evaluation (0: none)"};
inline constexpr OptionName kIntensity{"intensity", "--intensity", "auto | percentile | linear"};
inline constexpr OptionName kPoses{"poses", "--poses",
                                   "estimated (poses.txt) or truth (gt/poses.txt of synthetic scenes)"};
inline constexpr OptionName kSeed{"seed", "--seed", "Seed of view order and densification"};
inline constexpr OptionName kEvalEvery{"eval_every", "--eval-every",
                                       "Evaluate held-out views every K iterations (0: at the end)"};
inline constexpr OptionName kCheckpointEvery{
    "checkpoint_every", "--checkpoint-every",
    "Checkpoint every K iterations (0: none); a resume continues from "
    "the last"};
inline constexpr OptionName kProgressEvery{"progress_every", "--progress-every",
                                           "Progress line cadence (the report's loss curve)"};

}  // namespace litgs::host::train_option
