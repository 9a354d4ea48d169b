// train: the Gaussian map (`litgs-engine train`), resumed from its checkpoints after an interruption.
#include <stdexcept>

#include "host/partition/partition_option_names.h"
#include "host/run/stage.h"
#include "host/train/train_option_names.h"

namespace litgs::host::run {
namespace {

namespace fs = std::filesystem;

// train.init as `train --init` flags: "sfm" is the front end's points (the scene's sfm/, from match),
// "refined" the refine stage's (refine/points.pcd, scene frame).
std::vector<std::string> init_flags(const StageContext& c, std::vector<std::filesystem::path>& inputs) {
  const std::string& init = c.config.train.init;
  if (init == "auto" || init == "random" || init == "sfm") return {"--init", init};  // sfm: match's points
  if (init == "refined") {
    const fs::path points = c.scene() / "refine" / "points.pcd";
    if (!c.results.contains("refine") || !c.results["refine"].contains("scene"))
      throw std::invalid_argument("train.init is refined but the refine stage did not run (" +
                                  c.results.value("refine", nlohmann::json::object()).value("skipped", "") +
                                  ")");
    return {"--init", points.string(), "--init-frame", "scene"};
  }
  inputs.push_back(init);
  return {"--init", init};
}

// train.blocks other than 1: `train-blocks` partitions the scene (DIR/train/partition), trains each block
// with the train flags (on all its frames: the scene's held-out views are kept out of every block), merges.
StagePlan plan_in_blocks(const StageContext& c, StagePlan p, const std::vector<std::string>& train_flags) {
  namespace P = partition_option;
  const RunConfig::Train& o = c.config.train;
  const fs::path dir = c.stage_dir("train");
  p.command = {"train-blocks",  c.scene().string(), "--out",           dir.string(),
               P::kBlocks.flag, o.blocks,           "--holdout-every", std::to_string(o.holdout_every)};
  const std::vector<std::string> executor =
      option_flags(p.options, {P::kExecutor, P::kJobs, P::kGres, P::kMem, P::kTime, P::kSlurmPartition});
  p.command.insert(p.command.end(), executor.begin(), executor.end());
  for (const std::string& a : train_flags) p.command.push_back("--train-arg=" + a);
  for (const std::string& a : {std::string("--holdout-every"), std::string("0")})
    p.command.push_back("--train-arg=" + a);
  const fs::path rel = c.stage_rel("train");
  p.outputs = {rel / "point_cloud.ply", rel / "metrics.json"};
  p.resumable = true;  // the partition and the blocks already trained are kept
  p.resume_from = {rel / "partition"};
  p.notes.push_back("in blocks (" + o.blocks + ", executor " + o.executor + "): DIR/train/partition");
  return p;
}

StagePlan plan(const StageContext& c) {
  namespace T = train_option;
  const RunConfig::Train& o = c.config.train;
  const std::string scene = c.scene().string();
  const fs::path dir = c.stage_dir("train");
  StagePlan p;
  p.inputs = {scene};
  p.options = section_json(c.config, "train");
  if (o.blocks != "1") {
    for (const std::string& a : o.extra_args)
      if (a == "--holdout-every" || a.rfind("--holdout-every=", 0) == 0)
        throw std::invalid_argument(
            "train.extra_args: --holdout-every does not apply with train.blocks: each block trains on all "
            "its "
            "frames, and the scene's held-out views (train.holdout_every) are kept out of every block");
    std::vector<std::string> train_flags;
    for (const auto& flags :
         {option_flags(p.options, {T::kIterations, T::kDownscale, T::kStrategy, T::kMaxGaussians,
                                   T::kMcmcGrowth, T::kLambdaGeo, T::kIntensity, T::kPoses, T::kSeed,
                                   T::kCheckpointEvery, T::kProgressEvery}),
          init_flags(c, p.inputs), o.extra_args})
      train_flags.insert(train_flags.end(), flags.begin(), flags.end());
    return plan_in_blocks(c, p, train_flags);
  }
  p.command = {"train", scene, "--out", dir.string()};
  for (const auto& flags :
       {option_flags(p.options, {T::kIterations, T::kDownscale, T::kStrategy, T::kMaxGaussians,
                                 T::kMcmcGrowth, T::kLambdaGeo, T::kHoldoutEvery, T::kIntensity, T::kPoses,
                                 T::kSeed, T::kEvalEvery, T::kCheckpointEvery, T::kProgressEvery}),
        init_flags(c, p.inputs), std::vector<std::string>{"--trace", (dir / "trace.jsonl").string()},
        o.extra_args})
    p.command.insert(p.command.end(), flags.begin(), flags.end());
  const fs::path rel = c.stage_rel("train");
  p.outputs = {rel / "point_cloud.ply", rel / "metrics.json", rel / "trace.jsonl"};
  p.resumable = true;
  p.resume_args = {"--resume"};
  p.resume_from = {rel / "checkpoints", rel / "budget-search"};  // `train --resume` takes either up
  return p;
}

nlohmann::json result(const StageContext& c) {
  const fs::path dir = c.stage_dir("train");
  const nlohmann::json metrics =
      pick(read_stage_json(dir / "metrics.json"),
           {"iterations", "wall_s", "ms_per_iteration", "gaussians", "peak_device_bytes", "heldout_psnr",
            "heldout_ssim", "heldout_depth_plane_rmse_m"});
  return {{"model", (dir / "point_cloud.ply").string()}, {"metrics", metrics}};
}

}  // namespace

Stage train_stage() {
  return {"train", "Gaussian map on the Vulkan device", plan, result};
}

}  // namespace litgs::host::run
