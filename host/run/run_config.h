// run.yaml: every option of `litgs-engine run`, one section per stage, each key with its default and a
// comment. The defaults live here only: the YAML reader, `run --print-config` and the stages' manifests all
// walk the fields through for_each_field.
#pragma once

#include <cstdint>
#include <filesystem>
#include <nlohmann/json.hpp>
#include <string>
#include <vector>

#include "host/train/train_defaults.h"

namespace litgs::host::run {

// The defaults; each option is documented once, in for_each_field below (run --print-config prints it).
struct RunConfig {
  struct Import {
    std::string calib;
    std::string images;
    std::vector<std::string> livo2_config;
    std::string synth_preset = "facade";
    uint32_t synth_frames = 40;
    uint32_t synth_width = 160;
    uint32_t synth_height = 128;
    uint32_t synth_seed = 0;
    std::vector<std::string> extra_args;
  } import;
  struct Map {
    std::string build = "auto";
    double voxel = 0.1;
    bool deskew = true;
    std::vector<std::string> extra_args;
  } map;
  struct Match {
    bool enabled = true;
    std::string features = "sift";
    bool clahe = true;
    std::string pairs = "covisible";
    uint32_t max_keypoints = 3000;
    uint32_t threads = 0;
    std::vector<std::string> extra_args;
  } match;
  struct Refine {
    bool enabled = true;
    std::string tracks = "auto";
    std::string anchors = "auto";
    bool planes = true;
    uint32_t rounds = 8;  // refine's default (host/refine/refine.h)
    // auto: a pose prior on every frame (`refine --absolute-priors`) when INPUT is a Metashape or COLMAP
    // project, whose poses are a global photogrammetric solution, not a drifting odometry.
    std::string absolute_priors = "auto";
    uint32_t threads = 1;
    std::vector<std::string> extra_args;
  } refine;
  struct Train {
    // train's own defaults (host/train/train_defaults.h); ablate fixes the budget instead of growing it.
    uint32_t iterations = train_defaults::kIterations;
    double downscale = 1.0;
    std::string strategy = train_defaults::kStrategy;
    std::string max_gaussians = train_defaults::kMaxGaussians;
    double mcmc_growth = train_defaults::kMcmcGrowth;
    double lambda_geo = train_defaults::kLambdaGeo;
    std::string init = "auto";
    uint32_t holdout_every = 8;
    std::string intensity = "auto";
    std::string poses = "estimated";
    uint32_t seed = 0;
    // Unlike train's (0: at the end, none): the report draws the PSNR curve, and a stage resumes.
    uint32_t eval_every = 250;
    uint32_t checkpoint_every = 250;
    uint32_t progress_every = 50;
    std::vector<std::string> extra_args;
  } train;
  struct Eval {
    uint32_t emd_samples = 1000;
    uint32_t emd_rounds = 3;
    uint32_t seed = 0;
    bool geometry = true;
  } eval;
  struct Report {
    uint32_t max_views = 4;
  } report;
};

// Calls f(section, key, value&, comment) for every option, in the order run.yaml lists them.
template <class Config, class F>
void for_each_field(Config& c, F&& f) {
  f("import", "calib", c.import.calib, "ROS bag: M2DGR calibration_results.txt (or --calib)");
  f("import", "images", c.import.images,
    "Metashape/COLMAP: folder of the frames (default: images/ beside the XML or model)");
  f("import", "livo2_config", c.import.livo2_config, "FAST-LIVO2: camera and extrinsic YAML file(s)");
  f("import", "synth_preset", c.import.synth_preset,
    "synth inputs: facade | street | corridor (synth:NAME wins)");
  f("import", "synth_frames", c.import.synth_frames, "synth inputs: frames");
  f("import", "synth_width", c.import.synth_width, "synth inputs: image width");
  f("import", "synth_height", c.import.synth_height, "synth inputs: image height");
  f("import", "synth_seed", c.import.synth_seed, "synth inputs: seed");
  f("import", "extra_args", c.import.extra_args,
    "more flags for `litgs-engine import KIND` (or synth), as is");
  f("map", "build", c.map.build,
    "auto (when the scene has scans and no map) | always (from the scans, replacing the map) | never");
  f("map", "voxel", c.map.voxel, "voxel edge in metres (points averaged per voxel)");
  f("map", "deskew", c.map.deskew, "deskew scans with their per-point time field");
  f("map", "extra_args", c.map.extra_args, "more flags for `litgs-engine map`, as is");
  f("match", "enabled", c.match.enabled, "run the thermal front end (writes the scene's sfm/)");
  f("match", "features", c.match.features, "orb | sift | akaze");
  f("match", "clahe", c.match.clahe, "CLAHE before detection");
  f("match", "pairs", c.match.pairs,
    "covisible[:N] | sequential:N | exhaustive (see `litgs-engine match --help`)");
  f("match", "max_keypoints", c.match.max_keypoints, "keypoint budget per image");
  f("match", "threads", c.match.threads, "worker threads (0: all cores)");
  f("match", "extra_args", c.match.extra_args, "more flags for `litgs-engine match`, as is");
  f("refine", "enabled", c.refine.enabled, "refine the poses (poses.txt; the input kept as poses_prior.txt)");
  f("refine", "tracks", c.refine.tracks,
    "track source, as `refine --tracks`: auto or sfm (the front end's sfm/, written by match) | oracle "
    "(projected from a synth scene's true poses: an experiment, not the method)");
  f("refine", "anchors", c.refine.anchors,
    "anchor weights and priors, as `refine --anchors`: auto (with oracle tracks only: on the front end's "
    "tracks they made the poses worse, docs/refinement.md) | on | off");
  f("refine", "planes", c.refine.planes, "LiDAR point-to-plane term (off where the scene has no LiDAR map)");
  f("refine", "rounds", c.refine.rounds, "rounds of association, solve and rejection");
  f("refine", "absolute_priors", c.refine.absolute_priors,
    "auto (a pose prior on every frame when INPUT is a Metashape or COLMAP project: a global solution, not "
    "an odometry) | true | false");
  f("refine", "threads", c.refine.threads, "Ceres threads");
  f("refine", "extra_args", c.refine.extra_args, "more flags for `litgs-engine refine`, as is");
  f("train", "iterations", c.train.iterations, "training iterations");
  f("train", "downscale", c.train.downscale, "divide image size and intrinsics by this");
  f("train", "strategy", c.train.strategy,
    "mcmc (a fixed budget; the default, ahead of capped adc on the real DUNR facade: docs/results.md) | adc "
    "(3DGS's densification, capped by max_gaussians)");
  f("train", "max_gaussians", c.train.max_gaussians,
    "MCMC budget (adc: cap): grow (the default: doubled inside one training while every 8th training view, "
    "held back meanwhile, still gains; docs/cli/train.md), a count (40000 for a fixed one), auto (from the "
    "surface the training views see) or search (one training per doubled budget and fold, while their "
    "validation PSNR still rises: slower, the reference grow was measured against; docs/budget.md)");
  f("train", "mcmc_growth", c.train.mcmc_growth, "MCMC: growth per refinement (fraction)");
  f("train", "lambda_geo", c.train.lambda_geo, "weight of the LiDAR point-to-plane loss");
  f("train", "init", c.train.init,
    "auto (LiDAR map, else match's points, else random) | random | sfm (match's points) | refined (refine's "
    "points) | a .ply/.pcd "
    "file");
  f("train", "holdout_every", c.train.holdout_every, "hold out every Nth frame for evaluation");
  f("train", "intensity", c.train.intensity, "auto | percentile | linear");
  f("train", "poses", c.train.poses, "estimated (poses.txt) | truth (gt/poses.txt)");
  f("train", "seed", c.train.seed, "view order and densification seed");
  f("train", "eval_every", c.train.eval_every, "held-out evaluation cadence (the report's PSNR curve)");
  f("train", "checkpoint_every", c.train.checkpoint_every,
    "checkpoint cadence: an interrupted run resumes from the last one");
  f("train", "progress_every", c.train.progress_every, "progress line cadence (the report's loss curve)");
  f("train", "extra_args", c.train.extra_args, "more flags for `litgs-engine train`, as is");
  f("eval", "emd_samples", c.eval.emd_samples, "EMD: points drawn from each side (exact assignment, O(N^3))");
  f("eval", "emd_rounds", c.eval.emd_rounds, "EMD: independent draws (mean, std)");
  f("eval", "seed", c.eval.seed, "EMD: seed");
  f("eval", "geometry", c.eval.geometry, "EMD and plane residuals");
  f("report", "max_views", c.report.max_views, "held-out views shown as pictures");
}

// Reads run.yaml: sections and keys as above, any of them may be left out (its default stays). An unknown
// section or key, a wrong type or a YAML syntax error is an io::IoError naming the file and the key.
// Keys left out keep `base`'s values.
RunConfig read_run_config(const std::filesystem::path& path, const RunConfig& base = RunConfig());
// The configuration as run.yaml text, with each key's comment (run --print-config prints the defaults).
std::string run_config_yaml(const RunConfig& config);
// {section: {key: value}} (run.json, manifests).
nlohmann::json to_json(const RunConfig& config);
// The options of one section (a stage's manifest records only its own).
nlohmann::json section_json(const RunConfig& config, const std::string& section);

}  // namespace litgs::host::run
