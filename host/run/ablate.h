// `litgs-engine ablate`: the method's ablations as sets of runs of the pipeline (host/run/pipeline.h) that
// share every stage whose options agree (RunOptions::shared_stages), written as Markdown tables.
//   refine    training on the input, the refined and the true poses (Table II): ATE, PSNR, SSIM,
//             depth-to-plane RMSE, seconds of refine and of training
//   lambda    lambda_geo 0, 0.2, 0.4, 0.6, 0.8: PSNR, SSIM, depth and centres to planes, EMD
//   features  ORB, SIFT, AKAZE, each with and without CLAHE (Table III): inlier ratio, verified pairs,
//             points; ATE, plane residual and PSNR where refine uses the front end's tracks
//   strategy  ADC and MCMC at 1/4, 1/2 and 1 times train.max_gaussians (auto or search: 5k, 20k, 80k and it):
//             Gaussians, PSNR, SSIM, seconds
#pragma once

#include <filesystem>
#include <functional>
#include <ostream>
#include <string>
#include <vector>

#include "host/run/run_config.h"

namespace litgs::host::run {

struct AblationVariant {
  std::string name;                // a file name: DIR/runs/<study>-<name>.json
  std::vector<std::string> cells;  // the table's first columns (what varies)
  std::function<void(RunConfig&)> apply;
  std::string until = "eval";
};

struct AblationStudy {
  std::string name;
  std::vector<std::string> varied;  // headers of the first columns
  std::vector<AblationVariant> variants;
  // The measured columns: header and how to read the cell from a run's record (run.json's content).
  std::vector<std::pair<std::string, std::function<std::string(const nlohmann::json&)>>> measured;
  std::string note;  // printed under the table
};

// The studies `names` names (refine, lambda, features, strategy, all, or a comma-separated list), built on
// `base`, each once, in that order.
// std::invalid_argument for another name.
std::vector<AblationStudy> ablation_studies(const std::string& names, const RunConfig& base);

// Only the variants named in `names` (a comma-separated list of AblationVariant::name, e.g.
// "sift-clahe,xfeat"; empty: all), studies left without any dropped. std::invalid_argument naming a name that
// is no variant of `studies`, with the names there are.
std::vector<AblationStudy> keep_variants(std::vector<AblationStudy> studies, const std::string& names);

// The settings every variant starts from: run's defaults, but a fixed budget of 40k Gaussians (run's default
// grows it). Each variant then differs from the others in its studied option only, where a budget grown (or
// searched) per variant would move with the studied option and be a second difference between the rows.
RunConfig ablation_base_config();

struct AblateOptions {
  std::string input;
  std::filesystem::path out_dir;
  std::string study = "all";
  std::string variants;  // keep_variants: empty, all of each study's
  RunConfig config = ablation_base_config();
  std::filesystem::path engine;
};

// Runs every variant (sharing stages), writes DIR/ablation.md (the tables, with the command) and
// DIR/ablation.json (every run's record), and returns the Markdown. A failing run stops it (StageFailed).
std::string run_ablation(const AblateOptions& options, const std::string& command_line, std::ostream& out);

}  // namespace litgs::host::run
