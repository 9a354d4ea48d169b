// The stage adapters' shared parts: run.yaml options as flags, and the scene copies of map, match, refine.
#include <gtest/gtest.h>
#include <sys/stat.h>
#include <unistd.h>

#include <algorithm>
#include <filesystem>
#include <fstream>

#include "host/run/ablate.h"
#include "host/run/stage.h"

namespace litgs::host::run {
namespace {

namespace fs = std::filesystem;

TEST(StageFlags, EveryKindOfValue) {
  const nlohmann::json section = {{"max_keypoints", 3000}, {"lambda_geo", 0.1}, {"features", "orb"},
                                  {"clahe", false},        {"deskew", true},    {"geometry", true},
                                  {"extra", {"--a", "b"}}};
  const std::vector<std::string> expected = {"--max-keypoints", "3000", "--lambda",   "0.10000000000000001",
                                             "--features",      "orb",  "--no-clahe", "--deskew",
                                             "--extra",         "--a",  "b"};
  EXPECT_EQ(option_flags(section, {"max_keypoints", "lambda_geo=--lambda", "features", "clahe=!--no-clahe",
                                   "deskew", "geometry=!--no-geometry", "extra"}),
            expected);
  EXPECT_THROW(option_flags(section, {"missing"}), nlohmann::json::out_of_range);
}

class SceneCopyTest : public ::testing::Test {
 protected:
  void SetUp() override {
    root_ = fs::temp_directory_path() / ("litgs-scene-copy-" + std::to_string(::getpid()));
    fs::remove_all(root_);
    for (const char* f : {"scene.yaml", "poses.txt", "thermal/1.png", "lidar/map.pcd", "sfm/tracks.txt"}) {
      fs::create_directories((root_ / "in" / f).parent_path());
      std::ofstream(root_ / "in" / f) << f;
    }
  }
  void TearDown() override { fs::remove_all(root_); }
  static nlink_t links(const fs::path& p) {
    struct stat s {};
    return ::stat(p.c_str(), &s) == 0 ? s.st_nlink : 0;
  }
  static std::string text(const fs::path& p) {
    std::ifstream in(p);
    return {std::istreambuf_iterator<char>(in), {}};
  }
  fs::path root_;
};

TEST_F(SceneCopyTest, CopiesLinksAndLeavesOutAsAsked) {
  const fs::path in = root_ / "in", out = root_ / "out";
  fs::create_directories(out);
  std::ofstream(out / "stale.txt") << "from an earlier run";
  make_scene_copy({in, {"poses.txt", "lidar"}, {"sfm"}}, out);
  EXPECT_FALSE(fs::exists(out / "stale.txt")) << "the copy mixed with what was there";
  EXPECT_FALSE(fs::exists(out / "sfm"));
  EXPECT_EQ(links(out / "thermal/1.png"), 2u) << "not hard-linked";
  EXPECT_EQ(links(out / "scene.yaml"), 2u);
  EXPECT_EQ(links(out / "poses.txt"), 1u) << "a file the stage changes must be a copy";
  EXPECT_EQ(links(out / "lidar/map.pcd"), 1u) << "a folder in `copy` is copied whole";
  // Changing the copy leaves the input alone.
  std::ofstream(out / "poses.txt") << "refined";
  std::ofstream(out / "lidar/map.pcd") << "rebuilt";
  EXPECT_EQ(text(in / "poses.txt"), "poses.txt");
  EXPECT_EQ(text(in / "lidar/map.pcd"), "lidar/map.pcd");
}

// Metashape and COLMAP poses are a global solution: refine gets a prior on every frame unless run.yaml says;
// other inputs leave it to refine, which reads the scene's poses_origin.
TEST(RefineStagePlan, AbsolutePriorsFollowTheInputUnlessSet) {
  StageContext c;
  c.out_dir = fs::temp_directory_path() / "litgs-refine-plan";
  c.results["import"] = {{"scene", (c.out_dir / "import" / "scene").string()}};
  fs::create_directories(c.out_dir / "import" / "scene" / "sfm");  // match ran: refine has tracks
  const auto priors = [&] {
    const auto command = refine_stage().plan(c).command;
    const auto at = std::find(command.begin(), command.end(), "--priors");
    return at == command.end() || at + 1 == command.end() ? std::string("(none)") : *(at + 1);
  };
  for (const InputKind kind : {InputKind::kMetashape, InputKind::kColmap}) {
    c.kind = kind;
    EXPECT_EQ(priors(), "absolute") << kind_name(kind);
  }
  for (const InputKind kind :
       {InputKind::kScene, InputKind::kSynthetic, InputKind::kRosBag, InputKind::kLivo2}) {
    c.kind = kind;
    EXPECT_EQ(priors(), "auto") << kind_name(kind);
  }
  c.config.refine.absolute_priors = "true";
  EXPECT_EQ(priors(), "absolute");
  c.kind = InputKind::kMetashape;
  c.config.refine.absolute_priors = "false";
  EXPECT_EQ(priors(), "odometry");
  c.config.refine.absolute_priors = "yes";
  EXPECT_THROW(priors(), std::invalid_argument);
}

TEST_F(SceneCopyTest, MissingSceneIsAnError) {
  EXPECT_THROW(make_scene_copy({root_ / "absent", {}, {}}, root_ / "out"), fs::filesystem_error);
}

}  // namespace
}  // namespace litgs::host::run

namespace litgs::host::run {
namespace {

TEST(AblationStudies, VariantsOfEachStudyAndABadName) {
  RunConfig base;
  base.train.max_gaussians = "8000";
  const auto all = ablation_studies("all", base);
  ASSERT_EQ(all.size(), 4u);
  ASSERT_EQ(all[0].variants.size(), 3u);  // input, refined, true poses
  EXPECT_EQ(all[1].variants.size(), 5u);  // lambda_geo 0 .. 0.8
  // orb, sift, akaze, xfeat (mnn) on inputs x1, x2, x3, xfeat + lighterglue, each without and with CLAHE
  ASSERT_EQ(all[2].variants.size(), 14u);
  RunConfig lighterglue = base;
  all[2].variants[13].apply(lighterglue);
  EXPECT_EQ(lighterglue.match.features, "xfeat");
  EXPECT_EQ(lighterglue.match.matcher, "lighterglue");
  EXPECT_TRUE(lighterglue.match.clahe);
  EXPECT_EQ(lighterglue.match.xfeat_scale, 1.0);
  RunConfig tripled = base;
  all[2].variants[11].apply(tripled);
  EXPECT_EQ(all[2].variants[11].name, "xfeat-x3-clahe");
  EXPECT_EQ(tripled.match.xfeat_scale, 3.0);
  EXPECT_EQ(tripled.match.features, "xfeat");
  ASSERT_EQ(all[3].variants.size(), 6u);  // adc, mcmc x 3 budgets
  RunConfig c = base;
  all[0].variants[0].apply(c);
  EXPECT_FALSE(c.refine.enabled);
  EXPECT_EQ(c.train.poses, "estimated");
  all[0].variants[1].apply(c);
  EXPECT_TRUE(c.refine.enabled);
  EXPECT_EQ(c.train.poses, "estimated");
  c = base;
  all[0].variants[2].apply(c);  // true poses: no refinement, gt/poses.txt for training and eval
  EXPECT_FALSE(c.refine.enabled);
  EXPECT_EQ(c.train.poses, "truth");
  c = base;
  all[3].variants[0].apply(c);
  EXPECT_EQ(c.train.strategy, "adc");
  EXPECT_EQ(c.train.max_gaussians, "2000");
  // The default tracks (auto) are the front end's: each feature type runs through eval. With oracle
  // tracks refine and train do not depend on the features, so the study stops after match.
  EXPECT_EQ(all[2].variants[0].until, "eval");
  c = base;
  all[2].variants[7].apply(c);  // XFeat on the device with CLAHE, its own matcher (auto: mnn)
  EXPECT_EQ(c.match.features, "xfeat");
  EXPECT_TRUE(c.match.clahe);
  EXPECT_EQ(c.match.matcher, "auto");
  base.refine.tracks = "oracle";
  EXPECT_EQ(ablation_studies("features", base)[0].variants[0].until, "match");
  EXPECT_THROW(ablation_studies("colour", base), std::invalid_argument);
}

TEST(AblationStudies, ACommaSeparatedListRunsEachStudyOnceInItsOrder) {
  RunConfig base;
  base.train.max_gaussians = "8000";
  const auto two = ablation_studies("strategy,refine,refine", base);
  ASSERT_EQ(two.size(), 2u);
  EXPECT_EQ(two[0].name, "refine");
  EXPECT_EQ(two[1].name, "strategy");
  try {
    ablation_studies("refine,colour", base);
    FAIL() << "an unknown study in the list was accepted";
  } catch (const std::invalid_argument& e) {
    EXPECT_NE(std::string(e.what()).find("'colour' is not a study"), std::string::npos) << e.what();
  }
  EXPECT_THROW(ablation_studies("refine,", base), std::invalid_argument);  // an empty name
}

TEST(AblationStudies, NamedVariantsKeepTheirStudiesOrderAndABadNameListsTheOthers) {
  RunConfig base;
  base.train.max_gaussians = "8000";
  const auto kept = keep_variants(ablation_studies("refine,features", base), "xfeat-clahe,off,sift");
  ASSERT_EQ(kept.size(), 2u);
  ASSERT_EQ(kept[0].variants.size(), 1u);
  EXPECT_EQ(kept[0].variants[0].name, "off");
  ASSERT_EQ(kept[1].variants.size(), 2u);  // in the study's order, not the list's
  EXPECT_EQ(kept[1].variants[0].name, "sift");
  EXPECT_EQ(kept[1].variants[1].name, "xfeat-clahe");
  const auto one_study = keep_variants(ablation_studies("refine,features", base), "on");
  ASSERT_EQ(one_study.size(), 1u);  // the features study had none left
  EXPECT_EQ(one_study[0].name, "refine");
  EXPECT_EQ(keep_variants(ablation_studies("lambda", base), "").at(0).variants.size(), 5u);
  try {
    keep_variants(ablation_studies("features", base), "sift,surf");
    FAIL() << "a name that is no variant was accepted";
  } catch (const std::invalid_argument& e) {
    const std::string what = e.what();
    EXPECT_NE(what.find("'surf' is not a variant"), std::string::npos) << what;
    EXPECT_NE(what.find("xfeat-lighterglue-clahe"), std::string::npos) << what;
  }
  EXPECT_THROW(keep_variants(ablation_studies("refine", base), "sift"), std::invalid_argument);
}

TEST(AblationStudies, TheStrategyStudyComparesADerivedBudgetWithFixedOnes) {
  RunConfig base;
  base.train.max_gaussians = "auto";
  const auto study = ablation_studies("strategy", base);
  ASSERT_EQ(study.at(0).variants.size(), 8u);  // adc, mcmc x 5k, 20k, 80k, auto
  RunConfig c = base;
  study[0].variants.back().apply(c);
  EXPECT_EQ(c.train.strategy, "mcmc");
  EXPECT_EQ(c.train.max_gaussians, "auto");
  base.train.max_gaussians = "many";
  EXPECT_THROW(ablation_studies("strategy", base), std::invalid_argument);
}

}  // namespace
}  // namespace litgs::host::run
