// `train --max-gaussians N|auto|search` and the budget search's records (host/train/budget_flag.h,
// host/train/budget_trial_record.h): the flag's parsing, budget.json read back on --resume, a search cut
// short restarting, and a finished trial reused only under its own key. The search's trainings need a
// device: the cli.train_budget_search* tests run them.
#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>
#include <string>

#include "host/train/budget_flag.h"
#include "host/train/budget_trial_record.h"
#include "host/train/checkpoint.h"

namespace litgs::host {
namespace {

namespace fs = std::filesystem;

class BudgetFlagTest : public ::testing::Test {
 protected:
  void SetUp() override {
    out_ =
        fs::temp_directory_path() /
        ("litgs-budget-flag-" + std::string(::testing::UnitTest::GetInstance()->current_test_info()->name()));
    fs::remove_all(out_);
    fs::create_directories(out_);
  }
  void TearDown() override { fs::remove_all(out_); }
  void write(const fs::path& file, const std::string& text) {
    fs::create_directories(file.parent_path());
    std::ofstream(file) << text;
  }
  static std::string error_of(const std::function<void()>& f) {
    try {
      f();
    } catch (const std::invalid_argument& e) {
      return e.what();
    }
    return "";
  }

  fs::path out_;
  TrainingData data_;
  std::vector<Eigen::Vector3d> no_map_;
  kernels::GaussianModel random_;
  BudgetInputs inputs() {
    BudgetInputs in;
    in.data = &data_;
    in.map_points = &no_map_;
    in.initial = &random_;
    in.initial_is_random = true;
    return in;
  }
};

TEST_F(BudgetFlagTest, ACountIsTakenAndAnythingElseIsRefusedByName) {
  EXPECT_EQ(resolve_max_gaussians("5000", inputs(), out_), 5000u);
  EXPECT_EQ(resolve_max_gaussians("4294967295", inputs(), out_), 4294967295u);
  for (const std::string bad : {"12k", "0", "-5", "4294967296", "", "1e6"})
    EXPECT_NE(error_of([&] {
                resolve_max_gaussians(bad, inputs(), out_);
              }).find("positive integer, auto, search or grow, not '" + bad + "'"),
              std::string::npos)
        << bad;
}

TEST_F(BudgetFlagTest, AutoWithoutAMapAndWithARandomInitializationHasNoSurfaceToMeasure) {
  EXPECT_NE(error_of([&] {
              resolve_max_gaussians("auto", inputs(), out_);
            }).find("no LiDAR map and the initialization is random"),
            std::string::npos);
  EXPECT_FALSE(fs::exists(out_ / "budget.json"));
}

TEST_F(BudgetFlagTest, AResumedRunReadsTheBudgetItRecorded) {
  BudgetInputs in = inputs();
  in.resume = true;
  EXPECT_NE(error_of([&] { resolve_max_gaussians("auto", in, out_); }).find("budget.json is missing"),
            std::string::npos);
  write(out_ / "budget.json", "{\"gaussians\": 1234}");
  EXPECT_EQ(resolve_max_gaussians("auto", in, out_), 1234u);
  EXPECT_EQ(resolve_max_gaussians("search", in, out_), 1234u);
  write(out_ / "budget.json", "{\"budget\": 1234}");
  EXPECT_NE(error_of([&] { resolve_max_gaussians("auto", in, out_); }).find("not a budget record"),
            std::string::npos);
  // Not resuming, search gives the search's cap until the search has run.
  EXPECT_EQ(resolve_max_gaussians("search", inputs(), out_), BudgetSearchOptions{}.max_budget);
}

TEST_F(BudgetFlagTest, ASearchCutShortStartsAgainReusingWhatItFinished) {
  std::string flag = "search";
  bool resume = true;
  // Cut short in the search (no budget.json, no checkpoint): search again, reusing finished trials.
  EXPECT_TRUE(restart_cut_short_search(flag, resume, out_));
  EXPECT_FALSE(resume);
  EXPECT_EQ(flag, "search");
  // Cut short after the search, before the final training's first checkpoint: train at the budget found.
  resume = true;
  write(out_ / "budget.json", "{\"gaussians\": 777}");
  EXPECT_FALSE(restart_cut_short_search(flag, resume, out_));
  EXPECT_FALSE(resume);
  EXPECT_EQ(flag, "777");
  // With a checkpoint of the final training there is something to resume: nothing changes.
  flag = "search";
  resume = true;
  write(checkpoint_path(out_, 100), "");
  EXPECT_FALSE(restart_cut_short_search(flag, resume, out_));
  EXPECT_TRUE(resume);
  EXPECT_EQ(flag, "search");
}

TEST_F(BudgetFlagTest, AFinishedTrialIsReusedOnlyUnderItsOwnKey) {
  const nlohmann::json key = {{"options", {{"iterations", 1000}}}, {"start", "abc"}};
  FinishedTrial t;
  t.psnr_db = 31.5;
  t.ssim = 0.9;
  t.view_psnr_db = {30.0, 33.0};
  t.gaussians = 4096;
  t.wall_s = 12.5;
  write_finished_trial(out_ / "trial", key, t);
  const std::optional<FinishedTrial> back = read_finished_trial(out_ / "trial", key);
  ASSERT_TRUE(back.has_value());
  EXPECT_EQ(back->psnr_db, 31.5);
  EXPECT_EQ(back->ssim, 0.9);
  EXPECT_EQ(back->view_psnr_db, t.view_psnr_db);
  EXPECT_EQ(back->gaussians, 4096u);
  EXPECT_EQ(back->wall_s, 12.5);
  nlohmann::json other = key;
  other["start"] = "abd";
  EXPECT_FALSE(read_finished_trial(out_ / "trial", other).has_value());
  EXPECT_FALSE(read_finished_trial(out_ / "missing", key).has_value());
  write(out_ / "trial" / "trial.json", "{ not json");
  EXPECT_FALSE(read_finished_trial(out_ / "trial", key).has_value());
}

}  // namespace
}  // namespace litgs::host
