// run's cost estimates (host/run/stage_estimate.h): what they scale with, the range of a grown budget, and
// the stages that have no estimate and say why.
#include <gtest/gtest.h>

#include "host/run/stage_estimate.h"
#include "run_test_support.h"

namespace litgs::host::run {
namespace {

RunSize synth_size(uint32_t frames, uint32_t width, uint32_t height) {
  const auto s = size_before_import(InputKind::kSynthetic, "synth:facade", [&] {
    RunConfig c;
    c.import.synth_frames = frames;
    c.import.synth_width = width;
    c.import.synth_height = height;
    return c;
  }());
  EXPECT_TRUE(s.has_value());
  return s.value_or(RunSize{});
}

EstimateDevice cpu_device() {
  return {"llvmpipe", true, 2};
}

double seconds(const std::string& stage, const RunSize& s, const RunConfig& c, const EstimateDevice& d) {
  const auto e = estimate_stage(stage, InputKind::kSynthetic, s, c, d);
  EXPECT_TRUE(e.has_value()) << stage;
  return e ? e->high_s : -1;
}

TEST(StageEstimate, GrowsWithFramesPixelsIterationsAndBudget) {
  RunConfig c;
  c.train.max_gaussians = "40000";
  const RunSize small = synth_size(40, 160, 128), more_frames = synth_size(80, 160, 128),
                larger = synth_size(40, 320, 256);
  for (const char* stage : {"import", "match", "refine"}) {
    EXPECT_GT(seconds(stage, more_frames, c, cpu_device()), seconds(stage, small, c, cpu_device())) << stage;
    EXPECT_GT(seconds(stage, larger, c, cpu_device()), seconds(stage, small, c, cpu_device())) << stage;
  }
  const double base = seconds("train", small, c, cpu_device());
  EXPECT_GT(seconds("train", larger, c, cpu_device()), base);
  RunConfig longer = c;
  longer.train.iterations *= 2;
  EXPECT_GT(seconds("train", small, longer, cpu_device()), 1.8 * base - 10);
  RunConfig bigger = c;
  bigger.train.max_gaussians = "160000";
  EXPECT_GT(seconds("train", small, bigger, cpu_device()), base);
  RunConfig halved = c;
  halved.train.downscale = 2;
  EXPECT_LT(seconds("train", larger, halved, cpu_device()), seconds("train", larger, c, cpu_device()));
  // A GPU trains the same run in a small share of a 2-core CPU device's time; more host cores speed a CPU
  // device up.
  EXPECT_LT(seconds("train", small, c, {"NVIDIA H200", false, 16}), 0.2 * base);
  EXPECT_LT(seconds("train", small, c, {"llvmpipe", true, 16}), base);
  // XFeat's network runs on the device: on a CPU device it costs more than SIFT, on a GPU less than there.
  RunConfig xfeat = c;
  xfeat.match.features = "xfeat";
  EXPECT_GT(seconds("match", larger, xfeat, cpu_device()), 3 * seconds("match", larger, c, cpu_device()));
  EXPECT_LT(seconds("match", larger, xfeat, {"NVIDIA H200", false, 2}),
            seconds("match", larger, xfeat, cpu_device()));
  RunConfig tripled = xfeat;  // the network on 9 times the pixels
  tripled.match.xfeat_scale = 3;
  EXPECT_GT(seconds("match", larger, tripled, cpu_device()),
            2 * seconds("match", larger, xfeat, cpu_device()));
}

TEST(StageEstimate, TheScansInTheRefinementCostTimeOnlyInTheRoundsTheyJoin) {
  const RunSize s = synth_size(60, 320, 256);
  RunConfig c;  // refine.scans on, 8 rounds: the scans are in the last four
  const auto with = estimate_stage("refine", InputKind::kSynthetic, s, c, cpu_device());
  ASSERT_TRUE(with.has_value());
  EXPECT_NE(with->basis.find("60 scans in the last 4 rounds"), std::string::npos) << with->basis;
  RunConfig without = c;
  without.refine.scans = false;
  const double no_scans = seconds("refine", s, without, cpu_device());
  EXPECT_GT(with->high_s, no_scans + 2);
  RunConfig two_more = c;
  two_more.refine.rounds = 10;
  EXPECT_GT(seconds("refine", s, two_more, cpu_device()), with->high_s);
  RunConfig before_they_join = c;
  before_they_join.refine.rounds = 4;
  EXPECT_DOUBLE_EQ(seconds("refine", s, before_they_join, cpu_device()), no_scans);
  RunConfig two_threads = c;  // run's refine takes one thread by default
  two_threads.refine.threads = 2;
  EXPECT_LT(seconds("refine", s, two_threads, cpu_device()), 0.8 * with->high_s);
}

TEST(StageEstimate, AGrownBudgetIsARangeAndStagesWithoutAModelSayWhy) {
  const RunSize s = synth_size(40, 320, 256);
  RunConfig c;
  c.train.max_gaussians = "grow";
  const auto grown = estimate_stage("train", InputKind::kSynthetic, s, c, cpu_device());
  ASSERT_TRUE(grown.has_value());
  EXPECT_GT(grown->high_s, 2 * grown->low_s);
  EXPECT_NE(grown->basis.find("10k-160k Gaussians"), std::string::npos) << grown->basis;
  EXPECT_NE(grown->basis.find("320x256"), std::string::npos) << grown->basis;

  std::string why;
  c.train.max_gaussians = "search";
  EXPECT_FALSE(estimate_stage("train", InputKind::kSynthetic, s, c, cpu_device(), &why).has_value());
  EXPECT_NE(why.find("search"), std::string::npos) << why;
  c.train.max_gaussians = "40000";
  EXPECT_FALSE(estimate_stage("train", InputKind::kSynthetic, s, c, EstimateDevice{}, &why).has_value());
  EXPECT_NE(why.find("no Vulkan device"), std::string::npos) << why;
  RunConfig blocks = c;  // one whole training's figure would mislead: the blocks' views overlap
  blocks.train.blocks = "auto";
  EXPECT_FALSE(estimate_stage("train", InputKind::kSynthetic, s, blocks, cpu_device(), &why).has_value());
  EXPECT_NE(why.find("blocks"), std::string::npos) << why;
  RunConfig lighterglue = c;  // the pairs are known after pair selection; each costs keypoints squared
  lighterglue.match.features = "xfeat";
  lighterglue.match.matcher = "lighterglue";
  EXPECT_FALSE(
      estimate_stage("match", InputKind::kSynthetic, s, lighterglue, cpu_device(), &why).has_value());
  EXPECT_NE(why.find("LighterGlue"), std::string::npos) << why;
  EXPECT_FALSE(estimate_stage("no-such-stage", InputKind::kSynthetic, s, c, cpu_device(), &why).has_value());
  EXPECT_NE(why.find("no-such-stage"), std::string::npos) << why;

  // Stages with nothing to do cost nothing: a synth scene has its map, a disabled match does not run.
  EXPECT_EQ(seconds("map", s, c, cpu_device()), 0.0);
  c.match.enabled = false;
  EXPECT_EQ(seconds("match", s, c, cpu_device()), 0.0);
}

TEST(StageEstimate, TextIsRoundedAsAnEstimate) {
  EXPECT_EQ(estimate_text({40, 40, ""}), "about 40 s");
  EXPECT_EQ(estimate_text({0.2, 0.2, ""}), "about 1 s");
  EXPECT_EQ(estimate_text({120, 420, ""}), "about 2-7 min");
  EXPECT_EQ(estimate_text({40, 420, ""}), "about 40 s to 7 min");
  EXPECT_EQ(estimate_text({7200, 7200, ""}), "about 2.0 h");
}

TEST(StageEstimate, ASceneDirectoryIsSizedFromItsFiles) {
  const std::filesystem::path scene = std::filesystem::path(LITGS_RUN_TEST_DIR) / "estimate-scene";
  std::filesystem::remove_all(scene);
  ASSERT_EQ(
      testing::run_engine("synth --preset facade --frames 12 --width 64 --height 48 --out " + scene.string())
          .status,
      0);
  const auto s = size_before_import(InputKind::kScene, scene, RunConfig{});
  ASSERT_TRUE(s.has_value());
  EXPECT_EQ(s->frames, 12u);
  EXPECT_EQ(s->width, 64u);
  EXPECT_EQ(s->height, 48u);
  EXPECT_TRUE(s->map_file);
  // A folder that is not a scene names the file it lacks.
  EXPECT_THROW(size_of_scene(scene / "thermal"), std::exception);
}

}  // namespace
}  // namespace litgs::host::run
