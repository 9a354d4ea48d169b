// What a checkpoint carries besides the model (its run record: options, evaluations, counters, resumes), the
// check of a resume's options against it, and the frame header of written models. CPU only.
#include <gtest/gtest.h>
#include <unistd.h>

#include <cmath>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <limits>
#include <random>

#include "host/train/checkpoint.h"
#include "host/train/output_frame.h"
#include "host/train/run_options.h"
#include "io/error.h"
#include "io/gaussian_ply.h"
#include "kernels/level/level_shared.h"

namespace litgs::host {
namespace {

namespace fs = std::filesystem;

class RunRecordTest : public ::testing::Test {
 protected:
  void SetUp() override {
    dir_ = fs::temp_directory_path() / ("litgs-run-record-" + std::to_string(::getpid()));
    fs::remove_all(dir_);
    fs::create_directories(dir_);
  }
  void TearDown() override { fs::remove_all(dir_); }

  static kernels::GaussianModel model(size_t n) {
    kernels::GaussianModel m;
    m.channels = 1;
    m.sh_degree = 1;
    m.resize(n);
    std::mt19937 rng(3);
    std::uniform_real_distribution<float> u(-1, 1);
    for (auto* v : {&m.means, &m.log_scales, &m.quats, &m.opacity_logits, &m.sh})
      for (auto& x : *v) x = u(rng);
    return m;
  }

  // A training data stand-in with two views (one held out), enough for run_options_json.
  static TrainingData data() {
    TrainingData d;
    d.width = 4;
    d.height = 2;
    d.world_offset_m = {1000, -2000, 30};
    for (int i = 0; i < 2; ++i) {
      TrainingView v;
      v.name = "frame" + std::to_string(i) + ".png";
      v.heldout = i == 0;
      v.camera.fx = v.camera.fy = 10;
      v.camera.t_cam_world = {0.1 * i, 0, 0};
      v.image.assign(8, 0.25f * static_cast<float>(i));
      d.views.push_back(v);
    }
    return d;
  }

  static Checkpoint checkpoint() {
    Checkpoint c;
    c.iteration = 20;
    c.view_order = {1, 0};
    c.order_position = 1;
    c.rng_state = "5489";
    c.state = kernels::TrainingState::fresh(model(3));
    c.record.options = run_options_json(TrainOptions{}, data());
    c.record.counters.adam_nonfinite_skips[kernels::kMeans] = 7;
    c.record.counters.adam_nonfinite_skips[kernels::kSh] = 1ull << 40;  // beyond 32 bits
    c.record.counters.culled_nonfinite = 3;
    c.record.counters.walks_cut_short = 2;
    c.record.counters.pruned_nonfinite = 1;
    c.record.counters.pruned_plane = 5;
    c.record.counters.densify_capped = 9;
    c.record.evaluations = {{10, 14.5, 0.5, 0.03}, {20, std::numeric_limits<double>::quiet_NaN(), 0.6, -1}};
    c.record.resumes = {{10, false}};
    return c;
  }

  fs::path dir_;
};

TEST_F(RunRecordTest, CheckpointKeepsOptionsEvaluationsCountersAndResumes) {
  const Checkpoint c = checkpoint();
  write_checkpoint(dir_ / "a.ckpt", c);
  const Checkpoint r = read_checkpoint(dir_ / "a.ckpt");
  EXPECT_TRUE(r.has_record);
  EXPECT_EQ(r.iteration, 20u);
  EXPECT_EQ(r.record.options, c.record.options);
  EXPECT_EQ(r.record.counters, c.record.counters);
  ASSERT_EQ(r.record.evaluations.size(), 2u);
  EXPECT_EQ(r.record.evaluations[0].iteration, 10u);
  EXPECT_EQ(r.record.evaluations[0].psnr_db, 14.5);
  EXPECT_EQ(r.record.evaluations[0].depth_plane_rmse_m, 0.03);
  EXPECT_TRUE(std::isnan(r.record.evaluations[1].psnr_db)) << "JSON has no NaN: written as null, read as NaN";
  EXPECT_EQ(r.record.evaluations[1].depth_plane_rmse_m, -1);
  EXPECT_EQ(r.record.resumes, c.record.resumes);
  EXPECT_EQ(r.state.model.means, c.state.model.means);
}

// A format-3 file without a level model ends with an empty level state: its 8-byte count, 0. Returns the
// file without it.
std::vector<char> without_level_state(const fs::path& path) {
  std::ifstream in(path, std::ios::binary);
  std::vector<char> bytes((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
  EXPECT_EQ(std::string(bytes.end() - 8, bytes.end()), std::string(8, '\0'));
  bytes.resize(bytes.size() - 8);
  return bytes;
}

// A format-2 file (before the level state): format 3 without its last array, magic "LITGSCK2".
TEST_F(RunRecordTest, FormatTwoCheckpointIsReadWithoutALevelState) {
  write_checkpoint(dir_ / "v3.ckpt", checkpoint());
  std::vector<char> bytes = without_level_state(dir_ / "v3.ckpt");
  bytes[7] = '2';
  std::ofstream(dir_ / "v2.ckpt", std::ios::binary)
      .write(bytes.data(), static_cast<std::streamsize>(bytes.size()));
  const Checkpoint r = read_checkpoint(dir_ / "v2.ckpt");
  EXPECT_TRUE(r.has_record);
  EXPECT_TRUE(r.level_state.empty());
  EXPECT_EQ(r.record.evaluations.size(), checkpoint().record.evaluations.size());
}

TEST_F(RunRecordTest, LevelStateRoundTripsAndMustBeWholeRows) {
  Checkpoint c = checkpoint();
  c.level_state.assign(3 * LEVEL_STRIDE, 0.25f);  // two frames and the shared row
  write_checkpoint(dir_ / "level.ckpt", c);
  EXPECT_EQ(read_checkpoint(dir_ / "level.ckpt").level_state, c.level_state);
  c.level_state.resize(LEVEL_STRIDE + 3);
  write_checkpoint(dir_ / "bad.ckpt", c);
  EXPECT_THROW(read_checkpoint(dir_ / "bad.ckpt"), io::IoError);
}

// A format-1 file (the layout before run records): the same fields, magic "LITGSCK1", nothing after
// max_radius. Made from a format-3 file by cutting its level state and record off.
TEST_F(RunRecordTest, FormatOneCheckpointIsReadWithoutARecord) {
  write_checkpoint(dir_ / "v3.ckpt", checkpoint());
  std::vector<char> bytes = without_level_state(dir_ / "v3.ckpt");
  const std::string record = to_json(checkpoint().record).dump();
  ASSERT_GT(bytes.size(), record.size() + 8);
  ASSERT_EQ(std::string(bytes.end() - static_cast<long>(record.size()), bytes.end()), record);
  bytes.resize(bytes.size() - record.size() - 8);
  bytes[7] = '1';
  std::ofstream(dir_ / "v1.ckpt", std::ios::binary)
      .write(bytes.data(), static_cast<std::streamsize>(bytes.size()));
  const Checkpoint r = read_checkpoint(dir_ / "v1.ckpt");
  EXPECT_FALSE(r.has_record);
  EXPECT_EQ(r.iteration, 20u);
  EXPECT_TRUE(r.record.evaluations.empty());
  EXPECT_EQ(r.record.counters, TrainingCounters{});
  EXPECT_EQ(r.state.model.means, checkpoint().state.model.means);
}

TEST_F(RunRecordTest, BadRecordIsAnErrorNamingTheFile) {
  write_checkpoint(dir_ / "a.ckpt", checkpoint());
  std::fstream f(dir_ / "a.ckpt", std::ios::in | std::ios::out | std::ios::binary);
  f.seekp(-2 - 8, std::ios::end);  // before the (empty) level state's count
  f.put('#');                      // the JSON's last characters: no longer JSON
  f.close();
  try {
    read_checkpoint(dir_ / "a.ckpt");
    FAIL() << "a corrupt run record was accepted";
  } catch (const io::IoError& e) {
    EXPECT_NE(std::string(e.what()).find("a.ckpt"), std::string::npos) << e.what();
    EXPECT_NE(std::string(e.what()).find("run record"), std::string::npos) << e.what();
  }
}

TEST_F(RunRecordTest, NewestCheckpointIgnoresTemporariesAndOtherNames) {
  fs::create_directories(dir_ / "checkpoints");
  for (const char* name :
       {"iter_20.ckpt", "iter_100.ckpt", "iter_300.ckpt.tmp-1-0", "iter_x.ckpt", "notes.txt"})
    std::ofstream(dir_ / "checkpoints" / name) << "x";
  EXPECT_EQ(newest_checkpoint(dir_).filename(), "iter_100.ckpt");
  EXPECT_TRUE(newest_checkpoint(dir_ / "nothing").empty());
}

TEST_F(RunRecordTest, ResumeWithTheSameOptionsHasNothingToSay) {
  const auto j = run_options_json(TrainOptions{}, data());
  EXPECT_TRUE(check_resume_options("x.ckpt", 20, j, j).empty());
}

TEST_F(RunRecordTest, ResumeRefusesEveryOtherDifferenceNamingOptionAndValues) {
  TrainOptions a, b;
  b.lambda_geo = 0.3;
  b.seed = 4;
  b.densify_grad_threshold = 0.0005f;
  b.deterministic = true;
  TrainingData d = data();
  TrainingData e = data();
  e.options.downscale = 2;
  e.views[1].image[0] = 0.5f;  // another target image
  try {
    check_resume_options("out/checkpoints/iter_20.ckpt", 20, run_options_json(a, d), run_options_json(b, e));
    FAIL() << "changed options were accepted";
  } catch (const std::invalid_argument& x) {
    const std::string m = x.what();
    for (const char* expected :
         {"out/checkpoints/iter_20.ckpt", "--lambda-geo: checkpoint 0.6, now 0.3",
          "--seed: checkpoint 0, now 4", "--densify-grad-threshold: checkpoint 0.0002, now 0.0005",
          "--deterministic: checkpoint false, now true", "--downscale: checkpoint 1.0, now 2.0",
          "target images", "6 settings differ"})
      EXPECT_NE(m.find(expected), std::string::npos) << "'" << expected << "' missing from:\n" << m;
  }
}

TEST_F(RunRecordTest, ResumeAllowsCadenceOutputFrameAndMoreIterationsWithNotes) {
  TrainOptions a, b;
  a.iterations = 40;
  b.iterations = 80;
  b.eval_every = 10;
  b.checkpoint_every = 10;
  b.progress_every = 1;
  b.recentred_output = true;
  const auto notes =
      check_resume_options("c.ckpt", 40, run_options_json(a, data()), run_options_json(b, data()));
  ASSERT_EQ(notes.size(), 5u);
  std::string all;
  for (const auto& n : notes) all += n + "\n";
  EXPECT_NE(all.find("--iterations: checkpoint 40, now 80: the run is extended"), std::string::npos) << all;
  EXPECT_NE(all.find("learning-rate decay"), std::string::npos) << all;
  EXPECT_NE(all.find("--recentred-output: checkpoint false, now true"), std::string::npos) << all;
  // Fewer iterations than the checkpoint has done cannot be resumed.
  b.iterations = 30;
  EXPECT_THROW(check_resume_options("c.ckpt", 40, run_options_json(a, data()), run_options_json(b, data())),
               std::invalid_argument);
}

TEST_F(RunRecordTest, ResumeRefusesAnotherSceneFrameOrHoldOutSplit) {
  TrainingData moved = data();
  moved.world_offset_m.x() += 1;
  TrainingData split = data();
  split.views[1].heldout = true;
  const auto j = run_options_json(TrainOptions{}, data());
  for (const TrainingData* d : {&moved, &split})
    EXPECT_THROW(check_resume_options("c.ckpt", 20, j, run_options_json(TrainOptions{}, *d)),
                 std::invalid_argument);
  try {
    check_resume_options("c.ckpt", 20, j, run_options_json(TrainOptions{}, split));
  } catch (const std::invalid_argument& x) {
    EXPECT_NE(std::string(x.what()).find("checkpoint 2 views, 1 held out, now 2 views, 2 held out"),
              std::string::npos)
        << x.what();
  }
}

TEST_F(RunRecordTest, OptionsTheCheckpointDidNotRecordAreAssumedUnchangedWithANote) {
  auto stored = run_options_json(TrainOptions{}, data());
  stored["train"].erase("mcmc_growth");
  const auto notes = check_resume_options("c.ckpt", 20, stored, run_options_json(TrainOptions{}, data()));
  ASSERT_EQ(notes.size(), 1u);
  EXPECT_NE(notes[0].find("train.mcmc_growth is not recorded"), std::string::npos) << notes[0];
}

TEST_F(RunRecordTest, ModelFrameHeaderRoundTrips) {
  ModelFrame f;
  f.world_offset_m = {1000.25, -2000.5, 1e-17};
  f.scene_world_offset_m = Eigen::Vector3d(1000.25, -2000.5, 0.1);
  io::write_gaussian_ply(dir_ / "m.ply", model(2), model_frame_comments(f));
  const ModelFrame r = read_model_frame(dir_ / "m.ply");
  EXPECT_EQ(r.world_offset_m, f.world_offset_m) << "17 significant digits: the same doubles";
  ASSERT_TRUE(r.scene_world_offset_m.has_value());
  EXPECT_EQ(*r.scene_world_offset_m, *f.scene_world_offset_m);
  EXPECT_EQ(io::read_gaussian_ply(dir_ / "m.ply").means, model(2).means)
      << "the comments leave the data alone";
  // A PLY without the lines (another trainer's): original world coordinates, scene unknown.
  io::write_gaussian_ply(dir_ / "plain.ply", model(2));
  const ModelFrame plain = read_model_frame(dir_ / "plain.ply");
  EXPECT_EQ(plain.world_offset_m, Eigen::Vector3d::Zero());
  EXPECT_FALSE(plain.scene_world_offset_m.has_value());
}

TEST_F(RunRecordTest, MalformedFrameHeaderIsAnErrorNamingTheFile) {
  io::write_gaussian_ply(dir_ / "bad.ply", model(2), {"litgs_world_offset_m 1 2"});
  try {
    read_model_frame(dir_ / "bad.ply");
    FAIL() << "two values accepted";
  } catch (const io::IoError& e) {
    EXPECT_NE(std::string(e.what()).find("bad.ply"), std::string::npos) << e.what();
  }
  EXPECT_THROW(io::write_gaussian_ply(dir_ / "x.ply", model(2), {"two\nlines"}), std::invalid_argument);
}

TEST_F(RunRecordTest, ShiftKeepsFloatPrecisionAndZeroLeavesBitsAlone) {
  kernels::GaussianModel m = model(100);
  m.means[0] = -0.0f;  // x + 0.0 would turn it into +0.0
  const Eigen::Vector3d offset(1000.25, -2000.5, 0);
  const kernels::GaussianModel far = shift_means(m, offset);
  const kernels::GaussianModel back = shift_means(far, -offset);
  for (size_t i = 0; i < m.size(); ++i) {
    // Half a float32 step at 2000 m: 2^-13 / 2 = 6.1e-5 m (at 1000 m: 3.1e-5).
    EXPECT_NEAR(back.means[3 * i], m.means[3 * i], 3.1e-5);
    EXPECT_NEAR(back.means[3 * i + 1], m.means[3 * i + 1], 6.2e-5);
    EXPECT_NEAR(far.means[3 * i], m.means[3 * i] + 1000.25, 3.1e-5);
    EXPECT_EQ(std::memcmp(&far.means[3 * i + 2], &m.means[3 * i + 2], sizeof(float)), 0) << "z not shifted";
  }
  EXPECT_TRUE(std::signbit(shift_means(m, Eigen::Vector3d::Zero()).means[0]));
  EXPECT_EQ(far.sh, m.sh);
}

}  // namespace
}  // namespace litgs::host
