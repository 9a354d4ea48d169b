// run.yaml: every option of `litgs-engine run`, one section per stage, each key with its default and a
// comment. The defaults live here only: the YAML reader, `run --print-config` and the stages' manifests all
// walk the fields through for_each_field.
#pragma once

#include <cstdint>
#include <filesystem>
#include <nlohmann/json.hpp>
#include <string>
#include <vector>

#include "host/eval/eval_option_names.h"
#include "host/frontend/match_option_names.h"
#include "host/lidar_map/map_option_names.h"
#include "host/partition/partition_option_names.h"
#include "host/refine/refine_option_names.h"
#include "host/train/train_defaults.h"
#include "host/train/train_option_names.h"

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
    std::string matcher = "auto";
    bool clahe = true;
    std::string pairs = "covisible";
    uint32_t max_keypoints = 3000;
    double xfeat_scale = 1;
    uint32_t threads = 0;
    std::vector<std::string> extra_args;
  } match;
  struct Refine {
    bool enabled = true;
    std::string tracks = "auto";
    std::string anchors = "auto";
    bool planes = true;
    bool scans = true;    // refine's default (host/refine/refine.h)
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
    // Training in blocks (host/partition/partition_option_names.h): "1" is one training of the whole scene.
    std::string blocks = "1";
    std::string executor = "local";
    uint32_t block_jobs = 1;
    std::string slurm_gres = "gpu:1";
    std::string slurm_mem;
    std::string slurm_time;
    std::string slurm_partition;
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
  // An option its command shares: the key and the help from the command's table (host/option_name.h).
  const auto named = [&f](const char* section, const OptionName& name, auto& value) {
    f(section, name.key, value, name.help);
  };
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
  named("map", map_option::kVoxel, c.map.voxel);
  named("map", map_option::kDeskew, c.map.deskew);
  f("map", "extra_args", c.map.extra_args, "more flags for `litgs-engine map`, as is");
  f("match", "enabled", c.match.enabled, "run the thermal front end (writes the scene's sfm/)");
  named("match", match_option::kFeatures, c.match.features);
  named("match", match_option::kMatcher, c.match.matcher);
  named("match", match_option::kClahe, c.match.clahe);
  named("match", match_option::kPairs, c.match.pairs);
  named("match", match_option::kMaxKeypoints, c.match.max_keypoints);
  named("match", match_option::kXfeatScale, c.match.xfeat_scale);
  named("match", match_option::kThreads, c.match.threads);
  f("match", "extra_args", c.match.extra_args, "more flags for `litgs-engine match`, as is");
  f("refine", "enabled", c.refine.enabled, "refine the poses (poses.txt; the input kept as poses_prior.txt)");
  named("refine", refine_option::kTracks, c.refine.tracks);
  named("refine", refine_option::kAnchors, c.refine.anchors);
  named("refine", refine_option::kPlanes, c.refine.planes);
  named("refine", refine_option::kScans, c.refine.scans);
  named("refine", refine_option::kRounds, c.refine.rounds);
  f("refine", "absolute_priors", c.refine.absolute_priors,
    "auto (a pose prior on every frame when INPUT is a Metashape or COLMAP project: a global solution, not "
    "an odometry) | true | false");
  named("refine", refine_option::kThreads, c.refine.threads);
  f("refine", "extra_args", c.refine.extra_args, "more flags for `litgs-engine refine`, as is");
  namespace T = train_option;
  namespace P = partition_option;
  named("train", T::kIterations, c.train.iterations);
  named("train", T::kDownscale, c.train.downscale);
  named("train", T::kStrategy, c.train.strategy);
  named("train", T::kMaxGaussians, c.train.max_gaussians);
  named("train", T::kMcmcGrowth, c.train.mcmc_growth);
  named("train", T::kLambdaGeo, c.train.lambda_geo);
  named("train", T::kInit, c.train.init);
  named("train", T::kHoldoutEvery, c.train.holdout_every);
  named("train", T::kIntensity, c.train.intensity);
  named("train", T::kPoses, c.train.poses);
  named("train", T::kSeed, c.train.seed);
  named("train", T::kEvalEvery, c.train.eval_every);
  named("train", T::kCheckpointEvery, c.train.checkpoint_every);
  named("train", T::kProgressEvery, c.train.progress_every);
  f("train", "extra_args", c.train.extra_args, "more flags for `litgs-engine train`, as is");
  named("train", P::kBlocks, c.train.blocks);
  named("train", P::kExecutor, c.train.executor);
  named("train", P::kJobs, c.train.block_jobs);
  named("train", P::kGres, c.train.slurm_gres);
  named("train", P::kMem, c.train.slurm_mem);
  named("train", P::kTime, c.train.slurm_time);
  named("train", P::kSlurmPartition, c.train.slurm_partition);
  named("eval", eval_option::kEmdSamples, c.eval.emd_samples);
  named("eval", eval_option::kEmdRounds, c.eval.emd_rounds);
  named("eval", eval_option::kSeed, c.eval.seed);
  named("eval", eval_option::kGeometry, c.eval.geometry);
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
