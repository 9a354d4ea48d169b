// eval: the model against its scene (`litgs-engine eval`), with the training run's view of the data.
#include <fstream>

#include "host/run/stage.h"

namespace litgs::host::run {
namespace {

namespace fs = std::filesystem;

StagePlan plan(const StageContext& c) {
  const RunConfig::Eval& o = c.config.eval;
  const RunConfig::Train& t = c.config.train;
  const std::string scene = c.results.at("import").at("scene").get<std::string>();
  const std::string model = c.results.at("train").at("model").get<std::string>();
  const fs::path dir = c.stage_dir("eval");
  StagePlan p;
  p.inputs = {scene, model};
  p.options = section_json(c.config, "eval");
  for (const char* key : {"downscale", "holdout_every", "intensity", "poses"})
    p.options["train." + std::string(key)] = section_json(c.config, "train")[key];
  p.command = {"eval",
               "--model",
               model,
               "--scene",
               scene,
               "--out",
               (dir / "eval.json").string(),
               "--views-out",
               (dir / "views").string(),
               "--downscale",
               number_arg(t.downscale),
               "--holdout-every",
               std::to_string(t.holdout_every),
               "--intensity",
               t.intensity,
               "--poses",
               t.poses,
               "--emd-samples",
               std::to_string(o.emd_samples),
               "--emd-rounds",
               std::to_string(o.emd_rounds),
               "--seed",
               std::to_string(o.seed)};
  if (!o.geometry) p.command.push_back("--no-geometry");
  p.outputs = {"eval/eval.json", "eval/views"};
  return p;
}

nlohmann::json result(const StageContext& c) {
  std::ifstream in(c.stage_dir("eval") / "eval.json");
  const nlohmann::json e = nlohmann::json::parse(in);
  nlohmann::json metrics = nlohmann::json::object();
  for (const char* key : {"psnr_db", "ssim", "mae_counts", "depth_plane_rmse_m", "centre_plane_rms_m",
                          "render_ms_per_frame", "gaussians", "heldout_views"})
    metrics[key] = e.at(key);
  if (e.at("emd").is_object()) {
    metrics["emd_m"] = e["emd"]["mean_m"];
    metrics["emd_floor_m"] = e["emd"]["floor_m"];
  }
  metrics["lpips"] = e.at("lpips");
  return {{"eval", (c.stage_dir("eval") / "eval.json").string()}, {"metrics", metrics}};
}

}  // namespace

Stage eval_stage() {
  return {"eval", "held-out PSNR/SSIM, EMD, plane residuals, render speed", true, plan, result};
}

}  // namespace litgs::host::run
