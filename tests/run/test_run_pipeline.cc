// `litgs-engine run` end to end on a small synthetic scene: stages, manifests, reruns, --from, and the bad
// inputs the issue names (unknown INPUT, a failing stage, a changed input, an interrupted stage).
#include <gtest/gtest.h>
#include <signal.h>
#include <sys/resource.h>
#include <sys/wait.h>
#include <unistd.h>

#include <chrono>
#include <map>
#include <thread>

#include "run_test_support.h"

namespace litgs::testing {
namespace {

namespace fs = std::filesystem;

const fs::path kRoot = LITGS_RUN_TEST_DIR;

std::string run_args(const std::string& input, const fs::path& dir, const fs::path& config,
                     const std::string& more = "") {
  return "run " + input + " --out " + dir.string() + " --config " + config.string() + " " + more;
}

// A fresh 16-frame 64x48 synthetic facade at `scene`.
bool make_small_scene(const fs::path& scene) {
  fs::remove_all(scene);
  return run_engine("synth --preset facade --frames 16 --width 64 --height 48 --out " + scene.string())
             .status == 0;
}

// Also the fixture of the report's browser test (tests/run/CMakeLists.txt): leaves kRoot/e2e behind.
TEST(RunPipeline, SyntheticEndToEndThenRerunsSkipAndFromForces) {
  const fs::path dir = kRoot / "e2e";
  fs::remove_all(dir);
  const fs::path config = write_text(kRoot / "e2e.yaml", small_run_yaml());
  CommandResult r = run_engine(run_args("synth:facade", dir, config));
  ASSERT_EQ(r.status, 0) << r.output;
  // The synthetic scene comes with its LiDAR map: map has nothing to do and says why.
  EXPECT_EQ(stage_status(dir, "map"),
            "skipped: scene has a LiDAR map already (map.build: always rebuilds it from the scans)");
  EXPECT_FALSE(fs::exists(dir / "map"));
  for (const char* stage : {"import", "match", "refine", "train", "eval", "report"}) {
    EXPECT_EQ(stage_status(dir, stage), "done") << stage;
    EXPECT_TRUE(fs::exists(dir / stage / "manifest.json")) << stage;
  }
  const nlohmann::json run = read_json_file(dir / "run.json");
  EXPECT_EQ(run["status"], "done");
  // train and eval used the refined scene.
  EXPECT_TRUE(fs::exists(dir / "refine" / "scene" / "poses_prior.txt"));
  EXPECT_NE(read_json_file(dir / "train" / "manifest.json")["command"].dump().find(
                (dir / "refine" / "scene").string()),
            std::string::npos);
  EXPECT_NE(read_json_file(dir / "eval" / "manifest.json")["command"].dump().find(
                (dir / "refine" / "scene").string()),
            std::string::npos);
  for (const auto& s : run["stages"])
    if (s["status"] == "done") {
      EXPECT_GT(s["seconds"].get<double>(), 0.0) << s;
      EXPECT_GT(s["peak_host_bytes"].get<double>(), 1e6) << s;  // a real process's resident set
      // Each stage that ran was estimated before it started (the synth scene's size is known up front).
      ASSERT_TRUE(s.contains("estimate_s")) << s;
      EXPECT_GT(s["estimate_s"][0].get<double>(), 0.0) << s;
      EXPECT_GE(s["estimate_s"][1].get<double>(), s["estimate_s"][0].get<double>()) << s;
    }
  // The whole run's estimate comes before the first stage starts.
  const size_t estimate_line = r.output.find("run: estimate (");
  ASSERT_NE(estimate_line, std::string::npos) << r.output;
  EXPECT_LT(estimate_line, r.output.find("run: [1/7] import"));
  EXPECT_NE(r.output.find("run: [5/7] train: estimate: about "), std::string::npos) << r.output;
  const nlohmann::json eval = read_json_file(dir / "eval" / "eval.json");
  EXPECT_GT(eval["psnr_db"].get<double>(), 5.0);
  // ATE before and after refinement: eval measures it with refine's Umeyama ATE at the same frames.
  const nlohmann::json refined = read_json_file(dir / "refine" / "scene" / "refine.json");
  ASSERT_TRUE(eval["trajectory"].is_object()) << eval["trajectory"];
  EXPECT_NEAR(eval["trajectory"]["ate_m"].get<double>(), refined["ate_after_m"].get<double>(), 1e-12);
  EXPECT_NEAR(eval["trajectory"]["ate_prior_m"].get<double>(), refined["ate_before_m"].get<double>(), 1e-12);
  EXPECT_EQ(eval["trajectory"]["top_view"]["truth"].size(), 16u);
  EXPECT_EQ(eval["trajectory"]["side_view"]["truth"].size(), 16u);
  EXPECT_NE(r.output.find("run: ATE "), std::string::npos) << r.output;
  EXPECT_EQ(eval["views"].size(), eval["heldout_views"].get<size_t>());
  // The synthetic scene has true depth: each view's covisible share and its PSNR there, where every pixel
  // is covisible the same as over the whole view.
  ASSERT_TRUE(eval["covisible_psnr_db"].is_number()) << eval["covisibility"];
  EXPECT_GT(eval["covisible_fraction"].get<double>(), 0.5);
  EXPECT_LE(eval["covisible_fraction"].get<double>(), 1.0);
  size_t fully_covisible = 0;
  for (const auto& v : eval["views"])
    if (v["covisible_fraction"].get<double>() == 1.0) {
      EXPECT_NEAR(v["covisible_psnr_db"].get<double>(), v["psnr_db"].get<double>(), 1e-9) << v;
      ++fully_covisible;
    }
  EXPECT_GT(fully_covisible, 0u) << "this scene's interior held-out views are seen whole by their neighbours";
  EXPECT_NE(r.output.find("of pixels a training view saw"), std::string::npos) << r.output;
  EXPECT_EQ(read_json_file(dir / "train" / "metrics.json")["heldout_views"], eval["heldout_views"]);
  EXPECT_NEAR(read_json_file(dir / "train" / "metrics.json")["heldout_psnr"].get<double>(),
              eval["psnr_db"].get<double>(), 1e-6);  // the same renders of the same views
  EXPECT_NE(r.output.find("report: " + (dir / "report.html").string()), std::string::npos) << r.output;
  EXPECT_TRUE(fs::exists(dir / "run.yaml"));

  // A rerun skips everything; --from eval reruns eval and report only.
  r = run_engine(run_args("synth:facade", dir, config));
  ASSERT_EQ(r.status, 0) << r.output;
  for (const char* stage : {"import", "match", "refine", "train", "eval", "report"})
    EXPECT_EQ(stage_status(dir, stage), "up to date");
  r = run_engine(run_args("synth:facade", dir, config, "--from eval"));
  ASSERT_EQ(r.status, 0) << r.output;
  EXPECT_EQ(stage_status(dir, "train"), "up to date");
  EXPECT_EQ(stage_status(dir, "eval"), "done");
  EXPECT_EQ(stage_status(dir, "report"), "done");
}

// A stage made by another engine build is not up to date: a rebuilt engine (here a copy with one byte more,
// run through LITGS_ENGINE) makes its stages again, and then skips them.
TEST(RunPipeline, AnotherEngineBuildRunsTheStagesAgain) {
  const fs::path dir = kRoot / "engine-build", other = kRoot / "engine-build-copy";
  fs::remove_all(dir);
  fs::remove(other);
  const fs::path config = write_text(kRoot / "engine-build.yaml", small_run_yaml());
  CommandResult r = run_engine(run_args("synth:facade", dir, config, "--until import"));
  ASSERT_EQ(r.status, 0) << r.output;
  ASSERT_EQ(stage_status(dir, "import"), "done");
  fs::copy_file(LITGS_ENGINE_BINARY, other);
  std::ofstream(other, std::ios::app) << '\n';
  ::setenv("LITGS_ENGINE", other.c_str(), 1);
  r = run_engine(run_args("synth:facade", dir, config, "--until import"));
  const std::string status_with_other_build = stage_status(dir, "import");
  const CommandResult again = run_engine(run_args("synth:facade", dir, config, "--until import"));
  ::unsetenv("LITGS_ENGINE");
  ASSERT_EQ(r.status, 0) << r.output;
  EXPECT_EQ(status_with_other_build, "done") << r.output;
  EXPECT_EQ(read_json_file(dir / "import" / "manifest.json")["engine"]["path"], other.string());
  ASSERT_EQ(again.status, 0) << again.output;
  EXPECT_EQ(stage_status(dir, "import"), "up to date");
}

std::map<std::string, std::string> file_contents(const fs::path& dir) {
  std::map<std::string, std::string> files;
  for (const auto& e : fs::recursive_directory_iterator(dir))
    if (e.is_regular_file()) {
      std::ifstream in(e.path(), std::ios::binary);
      files[fs::relative(e.path(), dir).string()] = {std::istreambuf_iterator<char>(in), {}};
    }
  return files;
}

// map, match and refine each change their own copy of the scene; the user's scene directory stays as it was.
TEST(RunStages, SceneStagesWorkOnCopiesAndLeaveTheInputAlone) {
  const fs::path dir = kRoot / "copies", scene = kRoot / "copies-scene";
  fs::remove_all(dir);
  ASSERT_TRUE(make_small_scene(scene));
  const auto before = file_contents(scene);
  const fs::path config = write_text(kRoot / "copies.yaml", small_run_yaml() + "map:\n  build: always\n");
  const CommandResult r = run_engine(run_args(scene.string(), dir, config, "--until refine"));
  ASSERT_EQ(r.status, 0) << r.output;
  for (const char* stage : {"map", "match", "refine"}) EXPECT_EQ(stage_status(dir, stage), "done") << stage;
  EXPECT_EQ(stage_status(dir, "import"), "done");  // a scene directory: nothing to run, used in place
  EXPECT_FALSE(fs::exists(dir / "import" / "scene"));
  EXPECT_EQ(file_contents(scene), before) << "a stage modified the INPUT";
  const fs::path refined = dir / "refine" / "scene";
  EXPECT_TRUE(fs::exists(dir / "map" / "scene" / "lidar" / "map.pcd"));
  EXPECT_TRUE(fs::exists(dir / "match" / "scene" / "sfm" / "frontend.json"));
  EXPECT_TRUE(fs::exists(refined / "sfm" / "frontend.json")) << "refine's copy lost match's output";
  EXPECT_EQ(file_contents(refined).at("poses_prior.txt"), before.at("poses.txt"));
  EXPECT_NE(file_contents(refined).at("poses.txt"), before.at("poses.txt")) << "poses not refined";
  const std::string frame =
      "thermal/" + fs::directory_iterator(scene / "thermal")->path().filename().string();
  EXPECT_TRUE(fs::equivalent(scene / frame, refined / frame)) << "unchanged files are hard links";
  const nlohmann::json run = read_json_file(dir / "run.json");
  EXPECT_TRUE(run["stages"][3]["metrics"]["ate_after_m"].is_number()) << run["stages"][3];
}

std::string init_refined(std::string yaml) {
  return yaml.replace(yaml.find("init: random"), 12, "init: refined");
}

// A stage with nothing to do says why: no scans, no ground truth for oracle tracks; refine without a
// LiDAR map runs without the plane term.
TEST(RunStages, NothingToDoSaysWhy) {
  const fs::path dir = kRoot / "why", scene = kRoot / "why-scene";
  fs::remove_all(dir);
  ASSERT_TRUE(make_small_scene(scene));
  // No LiDAR at all, as a photogrammetry import.
  fs::remove_all(scene / "lidar");
  std::ifstream in(scene / "scene.yaml");
  std::string yaml{std::istreambuf_iterator<char>(in), {}};
  const size_t at = yaml.find("lidar_map: true");
  ASSERT_NE(at, std::string::npos);
  write_text(scene / "scene.yaml", yaml.replace(at, 15, "lidar_map: false"));
  const fs::path config = write_text(kRoot / "why.yaml", small_run_yaml());
  CommandResult r = run_engine(run_args(scene.string(), dir, config, "--until refine"));
  ASSERT_EQ(r.status, 0) << r.output;
  EXPECT_EQ(stage_status(dir, "map"), "skipped: scene has no scans (lidar/scans/)");
  EXPECT_NE(r.output.find("map: skipped: scene has no scans"), std::string::npos) << r.output;
  EXPECT_EQ(stage_status(dir, "refine"), "done");
  EXPECT_NE(r.output.find("refine: note: the scene has no LiDAR map: refine runs without the plane term"),
            std::string::npos)
      << r.output;
  EXPECT_NE(read_json_file(dir / "refine" / "manifest.json")["command"].dump().find("--no-planes"),
            std::string::npos);
  // Without ground truth the oracle tracks cannot be made: refine is skipped, and its old folder goes.
  fs::remove_all(scene / "gt");
  r = run_engine(run_args(scene.string(), dir, config, "--until refine"));
  ASSERT_EQ(r.status, 0) << r.output;
  EXPECT_EQ(stage_status(dir, "refine"),
            "skipped: refine.tracks is oracle and the scene has no gt/poses.txt to make them from");
  EXPECT_FALSE(fs::exists(dir / "refine"));
  // run's default track source (auto) refines a scene without ground truth, as real data, from the front
  // end's tracks (match's sfm/). What it did (refined, kept the priors, stopped) is written to refine.json
  // and to run.json's metrics, with the track source.
  std::string yaml_auto = small_run_yaml();
  yaml_auto.replace(yaml_auto.find("tracks: oracle"), 14, "tracks: auto");
  const fs::path auto_tracks = write_text(kRoot / "why-auto.yaml", yaml_auto);
  r = run_engine(run_args(scene.string(), dir, auto_tracks, "--until refine"));
  ASSERT_EQ(r.status, 0) << r.output;
  EXPECT_EQ(stage_status(dir, "refine"), "done");
  const nlohmann::json auto_refine = read_json_file(dir / "refine" / "scene" / "refine.json");
  EXPECT_EQ(auto_refine["tracks"], "sfm") << auto_refine.dump();
  const std::string outcome = auto_refine.value("outcome", "");
  EXPECT_TRUE(outcome == "refined" || outcome == "kept the priors" || outcome == "stopped")
      << auto_refine.dump();
  const nlohmann::json run_json = read_json_file(dir / "run.json");
  for (const auto& stage : run_json["stages"])
    if (stage["name"] == "refine") {
      EXPECT_EQ(stage["metrics"]["outcome"], outcome) << stage.dump();
      EXPECT_EQ(stage["metrics"]["tracks"], "sfm") << stage.dump();
    }
  // Training from refine's points needs refine: the run stops at train and says why.
  r = run_engine(run_args(scene.string(), dir, config, "--until refine"));
  ASSERT_EQ(r.status, 0) << r.output;
  const fs::path refined_init = write_text(kRoot / "why-refined.yaml", init_refined(small_run_yaml()));
  r = run_engine(run_args(scene.string(), dir, refined_init, "--until train"));
  EXPECT_NE(r.status, 0);
  EXPECT_NE(r.output.find("stage 'train' failed: train.init is refined but the refine stage did not run "
                          "(refine.tracks is oracle and the scene has no gt/poses.txt"),
            std::string::npos)
      << r.output;
}

// train.init: refined starts the Gaussians from refine's points (scene frame).
TEST(RunStages, TrainStartsFromRefinedPoints) {
  const fs::path dir = kRoot / "refined-init";
  fs::remove_all(dir);
  const fs::path config = write_text(kRoot / "refined-init.yaml", init_refined(small_run_yaml("", 20)));
  const CommandResult r = run_engine(run_args("synth:facade", dir, config, "--until train"));
  ASSERT_EQ(r.status, 0) << r.output;
  const size_t at =
      r.output.find(" Gaussians from " + (dir / "refine" / "scene" / "refine" / "points.pcd").string());
  ASSERT_NE(at, std::string::npos) << r.output;
  // As many Gaussians as refine wrote points (the PCD header's POINTS line).
  const size_t init = r.output.rfind("init ", at);
  std::ifstream pcd(dir / "refine" / "scene" / "refine" / "points.pcd");
  size_t points = 0;
  for (std::string line; std::getline(pcd, line) && line.rfind("DATA", 0) != 0;)
    if (line.rfind("POINTS ", 0) == 0) points = std::stoul(line.substr(7));
  EXPECT_GT(points, 0u);
  EXPECT_EQ(std::stoul(r.output.substr(init + 5, at - init - 5)), points) << r.output;
}

// train.blocks: 2 trains the scene as two blocks (train-blocks, the local executor) and merges them; eval
// scores the merged model on the whole scene; a rerun finds the stage done.
TEST(RunStages, TrainInBlocksMergesAndEvaluatesTheWholeScene) {
  const fs::path dir = kRoot / "blocks";
  fs::remove_all(dir);
  const fs::path config =
      write_text(kRoot / "blocks.yaml", small_run_yaml("  blocks: \"2\"\n  block_jobs: 2\n", 20));
  const CommandResult r = run_engine(run_args("synth:street", dir, config));
  ASSERT_EQ(r.status, 0) << r.output;
  const nlohmann::json metrics = read_json_file(dir / "train" / "metrics.json");
  ASSERT_TRUE(metrics.is_object()) << r.output;
  ASSERT_EQ(metrics["blocks"].size(), 2u);
  size_t kept = 0;
  for (const auto& b : metrics["blocks"]) {
    EXPECT_EQ(b["state"], "trained");
    EXPECT_GT(b["kept"].get<size_t>(), 0u);
    EXPECT_GT(b["peak_device_bytes"].get<double>(), 0) << "gathered from the block's own metrics.json";
    kept += b["kept"].get<size_t>();
    std::ifstream trace(dir / "train" / b["trace"].get<std::string>());
    EXPECT_TRUE(trace.good()) << "each block reports its progress to its own trace: " << b["trace"];
  }
  // The report draws each block's curve: its data block holds both, each with its progress records.
  std::ifstream report_file(dir / "report.html");
  const std::string report(std::istreambuf_iterator<char>(report_file), {});
  const size_t data = report.find("id=data>");
  ASSERT_NE(data, std::string::npos);
  const nlohmann::json charts =
      nlohmann::json::parse(report.substr(data + 8, report.find("</script>", data) - data - 8));
  ASSERT_EQ(charts["blocks"].size(), 2u);
  for (const auto& b : charts["blocks"]) EXPECT_FALSE(b["curve"].empty()) << b["name"];
  EXPECT_EQ(metrics["gaussians"].get<size_t>(), kept);
  const nlohmann::json eval = read_json_file(dir / "eval" / "eval.json");
  ASSERT_TRUE(eval.is_object()) << r.output;
  EXPECT_EQ(eval["gaussians"].get<size_t>(), kept) << "eval scored the merged model";
  const CommandResult again = run_engine(run_args("synth:street", dir, config));
  ASSERT_EQ(again.status, 0) << again.output;
  EXPECT_EQ(stage_status(dir, "train"), "up to date") << again.output;
}

// Blocks train on all their frames (the scene's held-out views are kept out of every block): a
// --holdout-every among train.extra_args would reach each block's train after the blocks' own and clash, so
// the train stage refuses it by name.
TEST(RunBadInput, HoldoutEveryAmongExtraArgsWithBlocksIsRefused) {
  const fs::path dir = kRoot / "blocks-holdout";
  fs::remove_all(dir);
  const fs::path config = write_text(
      kRoot / "blocks-holdout.yaml",
      "import:\n  synth_frames: 16\n  synth_width: 64\n  synth_height: 48\nmatch:\n  enabled: false\n"
      "refine:\n  enabled: false\ntrain:\n  blocks: \"2\"\n  extra_args: [\"--holdout-every\", \"4\"]\n");
  const CommandResult r = run_engine(run_args("synth:street", dir, config, "--until train"));
  EXPECT_NE(r.status, 0);
  EXPECT_NE(r.output.find("train.extra_args: --holdout-every does not apply with train.blocks"),
            std::string::npos)
      << r.output;
  EXPECT_FALSE(fs::exists(dir / "train" / "partition")) << "refused before partitioning";
}

TEST(RunBadInput, UnknownInputKind) {
  const fs::path dir = kRoot / "unknown";
  fs::remove_all(dir);
  const fs::path notes = write_text(kRoot / "notes.txt", "not a dataset\n");
  const CommandResult r = run_engine("run " + notes.string() + " --out " + dir.string());
  EXPECT_NE(r.status, 0);
  EXPECT_NE(r.output.find("unknown kind of input"), std::string::npos) << r.output;
  EXPECT_NE(r.output.find("expected a scene directory"), std::string::npos) << r.output;
  EXPECT_FALSE(fs::exists(dir / "run.json"));
}

TEST(RunBadInput, FailingStageStopsNamesItAndKeepsEarlierOutputs) {
  const fs::path dir = kRoot / "failing";
  fs::remove_all(dir);
  const fs::path config = write_text(kRoot / "failing.yaml", small_run_yaml("  strategy: bogus\n"));
  const CommandResult r = run_engine(run_args("synth:facade", dir, config));
  EXPECT_NE(r.status, 0);
  EXPECT_NE(r.output.find("stage 'train' failed"), std::string::npos) << r.output;
  // Why: the child's own message, in the output and in run.json.
  EXPECT_NE(r.output.find("stage 'train' failed: exit status 105: --strategy: bogus not in {adc,mcmc}"),
            std::string::npos)
      << r.output;
  EXPECT_TRUE(fs::exists(dir / "import" / "manifest.json"));
  EXPECT_TRUE(fs::exists(dir / "import" / "scene" / "scene.yaml"));
  EXPECT_FALSE(fs::exists(dir / "train" / "manifest.json"));
  EXPECT_FALSE(fs::exists(dir / "eval"));
  EXPECT_EQ(stage_status(dir, "train"), "failed");
  EXPECT_EQ(read_json_file(dir / "run.json")["status"], "failed");
}

TEST(RunBadInput, ChangedInputRerunsTheStagesWithoutMixing) {
  const fs::path dir = kRoot / "changed", scene = kRoot / "changed-scene";
  fs::remove_all(dir);
  ASSERT_TRUE(make_small_scene(scene));
  const fs::path config = write_text(kRoot / "changed.yaml", small_run_yaml());
  CommandResult r = run_engine(run_args(scene.string(), dir, config, "--until train"));
  ASSERT_EQ(r.status, 0) << r.output;
  EXPECT_EQ(stage_status(dir, "eval"), "not run (after --until)");
  write_text(dir / "train" / "left-over.txt", "from the first input");
  r = run_engine(run_args(scene.string(), dir, config, "--until train"));
  ASSERT_EQ(r.status, 0) << r.output;
  EXPECT_EQ(stage_status(dir, "train"), "up to date");
  // Change the input: a new file in the scene directory.
  write_text(scene / "notes.txt", "changed");
  r = run_engine(run_args(scene.string(), dir, config, "--until train"));
  ASSERT_EQ(r.status, 0) << r.output;
  EXPECT_EQ(stage_status(dir, "import"), "done");
  EXPECT_EQ(stage_status(dir, "train"), "done");
  EXPECT_FALSE(fs::exists(dir / "train" / "left-over.txt")) << "the rerun mixed with the old stage folder";
  EXPECT_EQ(read_json_file(dir / "train" / "metrics.json")["resumes"].size(), 0u)
      << "resumed the old input's run";
}

// Starts `litgs-engine ARGS` without waiting (its output in kRoot/NAME.log); its pid, 0 if it did not start.
pid_t start_in_background(const std::string& args, const std::string& name) {
  const std::string command = std::string(LITGS_ENGINE_BINARY) + " " + args + " > " +
                              (kRoot / (name + ".log")).string() + " 2>&1 & echo $! > " +
                              (kRoot / (name + ".pid")).string();
  if (std::system(command.c_str()) != 0) return 0;
  pid_t pid = 0;
  std::ifstream(kRoot / (name + ".pid")) >> pid;
  return pid;
}

TEST(RunBadInput, InterruptedStageIsNotTakenAsDone) {
  const fs::path dir = kRoot / "interrupted";
  fs::remove_all(dir);
  // Long enough to be killed after its first checkpoint (iteration 20).
  const fs::path config = write_text(kRoot / "interrupted.yaml", small_run_yaml("", 400));
  const pid_t pid = start_in_background(run_args("synth:facade", dir, config), "interrupted");
  ASSERT_GT(pid, 0);
  const auto start = std::chrono::steady_clock::now();
  while (!fs::exists(dir / "train" / "checkpoints" / "iter_20.ckpt")) {
    ASSERT_LT(std::chrono::steady_clock::now() - start, std::chrono::seconds(300)) << "no checkpoint";
    std::this_thread::sleep_for(std::chrono::milliseconds(20));
  }
  ASSERT_EQ(::kill(pid, SIGKILL), 0);  // the runner; its train child dies with it (PR_SET_PDEATHSIG)
  std::this_thread::sleep_for(std::chrono::milliseconds(500));
  EXPECT_FALSE(fs::exists(dir / "train" / "manifest.json"));
  EXPECT_EQ(stage_status(dir, "train"), "");  // run.json was last written after import

  CommandResult r = run_engine(run_args("synth:facade", dir, config));
  ASSERT_EQ(r.status, 0) << r.output;
  EXPECT_EQ(stage_status(dir, "import"), "up to date");
  EXPECT_NE(r.output.find("train: Gaussian map on the Vulkan device (resuming from train/checkpoints)"),
            std::string::npos)
      << r.output;
  const nlohmann::json metrics = read_json_file(dir / "train" / "metrics.json");
  ASSERT_GE(metrics["resumes"].size(), 1u);
  EXPECT_GE(metrics["resumes"][0]["from_iteration"].get<int>(), 20);
  EXPECT_EQ(metrics["iterations"], 400);

  // A half-written output under a complete manifest (a crash of something else writing there, a full disk):
  // the outputs' hashes no longer match, so the stage is not taken as done.
  const fs::path eval_json = dir / "eval" / "eval.json";
  const auto size = fs::file_size(eval_json);
  fs::resize_file(eval_json, size / 2);
  r = run_engine(run_args("synth:facade", dir, config));
  ASSERT_EQ(r.status, 0) << r.output;
  EXPECT_EQ(stage_status(dir, "train"), "up to date");
  EXPECT_EQ(stage_status(dir, "eval"), "done");
  EXPECT_TRUE(read_json_file(eval_json).is_object());
}

// A run killed in the budget search (`train.max_gaussians: search`) has no checkpoint yet, but finished
// trials: the rerun continues the stage and reuses them instead of starting the search again.
TEST(RunBadInput, InterruptedBudgetSearchContinues) {
  const fs::path dir = kRoot / "interrupted-search";
  fs::remove_all(dir);
  std::string yaml = small_run_yaml("", 200);
  yaml.replace(yaml.find("max_gaussians: 3000"), 19, "max_gaussians: search");
  const fs::path config = write_text(kRoot / "interrupted-search.yaml", yaml);
  const pid_t pid = start_in_background(run_args("synth:facade", dir, config), "interrupted-search");
  ASSERT_GT(pid, 0);
  const auto a_trial_finished = [&] {
    std::error_code ec;  // the folders appear while this looks
    for (fs::recursive_directory_iterator it(dir / "train" / "budget-search", ec), end; !ec && it != end;
         it.increment(ec))
      if (it->path().filename() == "trial.json") return true;
    return false;
  };
  const auto start = std::chrono::steady_clock::now();
  while (!a_trial_finished()) {
    ASSERT_LT(std::chrono::steady_clock::now() - start, std::chrono::seconds(300)) << "no finished trial";
    std::this_thread::sleep_for(std::chrono::milliseconds(20));
  }
  ASSERT_EQ(::kill(pid, SIGKILL), 0);
  std::this_thread::sleep_for(std::chrono::milliseconds(500));
  ASSERT_FALSE(fs::exists(dir / "train" / "budget.json")) << "killed too late: the search had finished";

  const CommandResult r = run_engine(run_args("synth:facade", dir, config));
  ASSERT_EQ(r.status, 0) << r.output;
  EXPECT_NE(r.output.find("train: Gaussian map on the Vulkan device (resuming from train/budget-search)"),
            std::string::npos)
      << r.output;
  std::ifstream log(dir / "train" / "log.txt");
  const std::string train_log{std::istreambuf_iterator<char>(log), {}};
  EXPECT_NE(train_log.find("the budget search had not finished; it continues"), std::string::npos)
      << train_log;
  EXPECT_NE(train_log.find("of the trainings reused"), std::string::npos) << train_log;
  const nlohmann::json budget = read_json_file(dir / "train" / "budget.json");
  ASSERT_TRUE(budget.is_object());
  // The report shows how the budget was chosen: the kept budget's row is marked.
  std::ifstream report(dir / "report.html");
  const std::string html{std::istreambuf_iterator<char>(report), {}};
  EXPECT_NE(
      html.find("<tr class=kept><td>" + std::to_string(budget.at("gaussians").get<uint64_t>()) + "</td>"),
      std::string::npos);
}

// `litgs-engine ARGS` with every file it (and its stages) write limited to `max_file_bytes`: writes past
// that fail with EFBIG (SIGXFSZ ignored, as the limit and the disposition pass to the stages' children), as
// on a full disk, without needing one.
CommandResult run_engine_with_file_limit(const std::string& args, rlim_t max_file_bytes) {
  const fs::path log = kRoot / "file-limit.log";
  fs::remove(log);
  const pid_t pid = ::fork();
  if (pid == 0) {
    const rlimit limit{max_file_bytes, max_file_bytes};
    ::setrlimit(RLIMIT_FSIZE, &limit);
    ::signal(SIGXFSZ, SIG_IGN);
    const std::string command =
        std::string(LITGS_ENGINE_BINARY) + " " + args + " > " + log.string() + " 2>&1";
    ::execl("/bin/sh", "sh", "-c", command.c_str(), static_cast<char*>(nullptr));
    ::_exit(127);
  }
  int status = -1;
  ::waitpid(pid, &status, 0);
  std::ifstream in(log);
  return {status, std::string{std::istreambuf_iterator<char>(in), {}}};
}

TEST(RunBadInput, FullDiskFailsTheStageWithoutAManifestAndARerunRedoesIt) {
  const fs::path dir = kRoot / "full-disk";
  fs::remove_all(dir);
  const fs::path config = write_text(kRoot / "full-disk.yaml", small_run_yaml());
  CommandResult r = run_engine(run_args("synth:facade", dir, config, "--until refine"));
  ASSERT_EQ(r.status, 0) << r.output;
  // 600 kB per file: run.json and the manifests fit, train's checkpoint (about 1 MB) does not.
  r = run_engine_with_file_limit(run_args("synth:facade", dir, config), 600'000);
  EXPECT_NE(r.status, 0);
  EXPECT_NE(r.output.find("stage 'train' failed: exit status 1: litgs-engine: error: " +
                          (dir / "train" / "checkpoints").string()),
            std::string::npos)
      << r.output;
  EXPECT_NE(r.output.find("write failed (disk full?)"), std::string::npos) << r.output;
  EXPECT_FALSE(fs::exists(dir / "train" / "manifest.json"));
  EXPECT_TRUE(fs::is_empty(dir / "train" / "checkpoints")) << "a half-written checkpoint was left";
  EXPECT_EQ(stage_status(dir, "train"), "failed");
  EXPECT_EQ(stage_status(dir, "refine"), "up to date");
  // With space again: train runs afresh (there is no checkpoint to continue from), then eval and report.
  r = run_engine(run_args("synth:facade", dir, config));
  ASSERT_EQ(r.status, 0) << r.output;
  EXPECT_EQ(r.output.find("resuming"), std::string::npos) << r.output;
  for (const char* stage : {"train", "eval", "report"}) EXPECT_EQ(stage_status(dir, stage), "done") << stage;
  EXPECT_EQ(read_json_file(dir / "train" / "metrics.json")["iterations"], 40);
}

// ablate on a scene without ground truth (as real data): the true-pose variant cannot run; its row says why
// and the other variants still run.
TEST(RunAblate, AVariantTheSceneCannotRunIsARowThatSaysWhy) {
  const fs::path dir = kRoot / "ablate-nogt", scene = kRoot / "ablate-nogt-scene";
  fs::remove_all(dir);
  ASSERT_TRUE(make_small_scene(scene));
  fs::remove_all(scene / "gt");
  const fs::path config = write_text(kRoot / "ablate-nogt.yaml", small_run_yaml());
  const CommandResult r = run_engine("ablate " + scene.string() + " --out " + dir.string() +
                                     " --study refine --config " + config.string());
  ASSERT_EQ(r.status, 0) << r.output;
  std::ifstream in(dir / "ablation.md");
  const std::string md{std::istreambuf_iterator<char>(in), {}};
  EXPECT_NE(md.find("| true (gt/poses.txt) | not run: stage 'train' failed"), std::string::npos) << md;
  EXPECT_NE(md.find("| input (unrefined) | - | "), std::string::npos) << md;  // no truth: no ATE, a PSNR
  EXPECT_EQ(md.find("| input (unrefined) | - | - |"), std::string::npos) << md;
}

// ablate: the variants share the stages their options agree on, and the table holds what the runs measured.
TEST(RunAblate, RefineStudySharesStagesAndWritesItsTable) {
  const fs::path dir = kRoot / "ablate";
  fs::remove_all(dir);
  const fs::path config = write_text(kRoot / "ablate.yaml", small_run_yaml());
  const CommandResult r =
      run_engine("ablate synth:facade --out " + dir.string() + " --study refine --config " + config.string());
  ASSERT_EQ(r.status, 0) << r.output;
  size_t imports = 0, refines = 0, trains = 0;
  for (const auto& e : fs::directory_iterator(dir / "stages")) {
    const std::string name = e.path().filename().string();
    imports += name.rfind("import-", 0) == 0;
    refines += name.rfind("refine-", 0) == 0;
    trains += name.rfind("train-", 0) == 0;
  }
  EXPECT_EQ(imports, 1u) << "the three runs did not share import";
  EXPECT_EQ(refines, 1u) << "only the run with refinement has a refine folder";
  EXPECT_EQ(trains, 3u);
  for (const char* stage : {"import", "match"})
    EXPECT_EQ(stage_status(dir / "runs", "refine-on", stage), "up to date") << stage;
  EXPECT_EQ(stage_status(dir / "runs", "refine-off", "refine"), "skipped: refine.enabled is false");
  EXPECT_EQ(stage_status(dir / "runs", "refine-truth", "refine"), "skipped: refine.enabled is false");
  // The true-pose run trains and evaluates its held-out views on gt/poses.txt; the other two on poses.txt.
  size_t truth_trains = 0, truth_evals = 0;
  for (const auto& e : fs::directory_iterator(dir / "stages")) {
    const std::string name = e.path().filename().string();
    if (name.rfind("train-", 0) != 0 && name.rfind("eval-", 0) != 0) continue;
    const std::string command = read_json_file(e.path() / "manifest.json")["command"].dump();
    const bool truth = command.find(R"("--poses","truth")") != std::string::npos;
    (name[0] == 't' ? truth_trains : truth_evals) += truth;
  }
  EXPECT_EQ(truth_trains, 1u);
  EXPECT_EQ(truth_evals, 1u);
  std::ifstream in(dir / "ablation.md");
  const std::string md{std::istreambuf_iterator<char>(in), {}};
  EXPECT_NE(md.find("| poses | ATE (m) | PSNR (dB) | covisible PSNR (dB) |"), std::string::npos) << md;
  const nlohmann::json on = read_json_file(dir / "runs" / "refine-on.json");
  char row[96];
  // The covisible PSNR is eval's, as written in the run's record (the synthetic scene has true depth).
  std::snprintf(row, sizeof row, "| refined | %.4f | %.2f | %.2f |",
                on["stages"][5]["metrics"]["ate_m"].get<double>(),
                on["stages"][5]["metrics"]["psnr_db"].get<double>(),
                on["stages"][5]["metrics"]["covisible_psnr_db"].get<double>());
  EXPECT_NE(md.find(row), std::string::npos) << row << "\n" << md;
  // The truth row's ATE is measured (eval scores gt/poses.txt, which that run trained on), not written in.
  const nlohmann::json truth = read_json_file(dir / "runs" / "refine-truth.json");
  const double truth_ate = truth["stages"][5]["metrics"]["ate_m"].get<double>();
  EXPECT_LT(truth_ate, 1e-9);
  std::snprintf(row, sizeof row, "| true (gt/poses.txt) | %.4f |", truth_ate);
  EXPECT_NE(md.find(row), std::string::npos) << row << "\n" << md;
  EXPECT_NE(md.find("Made by `litgs-engine ablate synth:facade"), std::string::npos);
}

}  // namespace
}  // namespace litgs::testing

namespace litgs::testing {
namespace {

// eval on its own, on the end-to-end test's run folder (its fixture).
TEST(RunEval, JsonStatesLpipsAndRefusesASceneWithoutHeldOutViews) {
  const fs::path dir = kRoot / "e2e";
  ASSERT_TRUE(fs::exists(dir / "train" / "point_cloud.ply")) << "RunPipeline.SyntheticEndToEnd* makes it";
  const std::string model = (dir / "train" / "point_cloud.ply").string(),
                    scene = (dir / "import" / "scene").string();
  CommandResult r = run_engine("eval --model " + model + " --scene " + scene +
                               " --holdout-every 4 --emd-samples 50 --json");
  ASSERT_EQ(r.status, 0) << r.output;
  const nlohmann::json j = nlohmann::json::parse(r.output.substr(r.output.find('{')));
  EXPECT_NE(j["lpips"].get<std::string>().find("not available"), std::string::npos);
  EXPECT_EQ(j["emd"]["samples"], 50);
  EXPECT_LE(j["emd"]["mean_m"].get<double>(), 1e3);
  r = run_engine("eval --model " + model + " --scene " + scene + " --holdout-every 0");
  EXPECT_NE(r.status, 0);
  EXPECT_NE(r.output.find("no held-out views to evaluate"), std::string::npos) << r.output;
}

}  // namespace
}  // namespace litgs::testing
