// train: the Gaussian map (`litgs-engine train`), resumed from its checkpoints after an interruption.
#include <fstream>

#include "host/run/stage.h"

namespace litgs::host::run {
namespace {

namespace fs = std::filesystem;

StagePlan plan(const StageContext& c) {
  const RunConfig::Train& o = c.config.train;
  const std::string scene = c.results.at("import").at("scene").get<std::string>();
  const fs::path dir = c.stage_dir("train");
  StagePlan p;
  p.inputs = {scene};
  if (o.init != "auto" && o.init != "random") p.inputs.push_back(o.init);
  p.options = section_json(c.config, "train");
  p.command = {"train",
               scene,
               "--out",
               dir.string(),
               "--iterations",
               std::to_string(o.iterations),
               "--downscale",
               number_arg(o.downscale),
               "--strategy",
               o.strategy,
               "--max-gaussians",
               std::to_string(o.max_gaussians),
               "--mcmc-growth",
               number_arg(o.mcmc_growth),
               "--lambda-geo",
               number_arg(o.lambda_geo),
               "--init",
               o.init,
               "--holdout-every",
               std::to_string(o.holdout_every),
               "--intensity",
               o.intensity,
               "--poses",
               o.poses,
               "--seed",
               std::to_string(o.seed),
               "--eval-every",
               std::to_string(o.eval_every),
               "--checkpoint-every",
               std::to_string(o.checkpoint_every),
               "--progress-every",
               std::to_string(o.progress_every),
               "--trace",
               (dir / "trace.jsonl").string()};
  p.command.insert(p.command.end(), o.extra_args.begin(), o.extra_args.end());
  p.outputs = {"train/point_cloud.ply", "train/metrics.json", "train/trace.jsonl"};
  p.resumable = true;
  p.resume_args = {"--resume"};
  return p;
}

nlohmann::json result(const StageContext& c) {
  const fs::path dir = c.stage_dir("train");
  std::ifstream in(dir / "metrics.json");
  const nlohmann::json m = nlohmann::json::parse(in);
  nlohmann::json metrics = nlohmann::json::object();
  for (const char* key : {"iterations", "wall_s", "ms_per_iteration", "gaussians", "peak_device_bytes",
                          "heldout_psnr", "heldout_ssim", "heldout_depth_plane_rmse_m"})
    if (m.contains(key)) metrics[key] = m[key];
  return {{"model", (dir / "point_cloud.ply").string()}, {"metrics", metrics}};
}

}  // namespace

Stage train_stage() {
  return {"train", "Gaussian map on the Vulkan device", true, plan, result};
}

}  // namespace litgs::host::run
