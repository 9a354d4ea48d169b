// eval: the model against its scene (`litgs-engine eval`), with the training run's view of the data.
#include "host/eval/eval_option_names.h"
#include "host/run/stage.h"
#include "host/train/train_option_names.h"

namespace litgs::host::run {
namespace {

namespace fs = std::filesystem;

StagePlan plan(const StageContext& c) {
  const std::string scene = c.scene().string();
  const std::string model = c.results.at("train").at("model").get<std::string>();
  const fs::path dir = c.stage_dir("eval");
  StagePlan p;
  p.inputs = {scene, model};
  p.options = section_json(c.config, "eval");
  const nlohmann::json train =
      pick(section_json(c.config, "train"), {"downscale", "holdout_every", "intensity", "poses"});
  for (const auto& [key, value] : train.items()) p.options["train." + key] = value;
  p.command = {"eval",
               "--model",
               model,
               "--scene",
               scene,
               "--out",
               (dir / "eval.json").string(),
               "--views-out",
               (dir / "views").string()};
  for (const auto& flags : {option_flags(train, {train_option::kDownscale, train_option::kHoldoutEvery,
                                                 train_option::kIntensity, train_option::kPoses}),
                            option_flags(p.options, {eval_option::kEmdSamples, eval_option::kEmdRounds,
                                                     eval_option::kSeed, eval_option::kGeometry})})
    p.command.insert(p.command.end(), flags.begin(), flags.end());
  p.outputs = {c.stage_rel("eval") / "eval.json", c.stage_rel("eval") / "views"};
  return p;
}

nlohmann::json result(const StageContext& c) {
  const nlohmann::json e = read_stage_json(c.stage_dir("eval") / "eval.json");
  nlohmann::json metrics = nlohmann::json::object();
  for (const char* key : {"psnr_db", "ssim", "mae_counts", "depth_plane_rmse_m", "centre_plane_rms_m",
                          "render_ms_per_frame", "gaussians", "heldout_views"})
    metrics[key] = e.at(key);
  if (e.at("emd").is_object()) {
    metrics["emd_m"] = e["emd"]["mean_m"];
    metrics["emd_floor_m"] = e["emd"]["floor_m"];
    metrics["emd_reference"] = e["emd"]["reference"];
  }
  if (e.value("observed_region", nlohmann::json()).is_object()) {
    metrics["observed_fraction"] = e["observed_region"]["reference_observed_fraction"];
    metrics["covered_fraction"] = e["observed_region"]["covered_fraction"];
  }
  for (const char* key : {"covisible_psnr_db", "covisible_fraction"})  // null where not measured
    metrics[key] = e.value(key, nlohmann::json());
  metrics["lpips"] = e.at("lpips");
  if (e.value("trajectory", nlohmann::json()).is_object())
    metrics.update(pick(e["trajectory"], {"ate_m", "ate_prior_m", "moved_mean_m", "moved_max_m"}));
  return {{"eval", (c.stage_dir("eval") / "eval.json").string()}, {"metrics", metrics}};
}

}  // namespace

Stage eval_stage() {
  return {"eval", "held-out PSNR/SSIM, EMD, plane residuals, render speed", plan, result};
}

}  // namespace litgs::host::run
