// What `train --resume` promises, on a small synthetic scene (lavapipe, validation on): with --deterministic
// a run interrupted after a checkpoint and resumed writes the bits of the uninterrupted run, metrics.json
// included (evaluations, counters); with float atomics the same quality within a stated tolerance; changed
// options are refused, allowed ones noted; a format-1 checkpoint is resumed with a warning.
#include <gtest/gtest.h>
#include <unistd.h>

#include <algorithm>
#include <cmath>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <limits>
#include <nlohmann/json.hpp>
#include <random>

#include "gpu_test.h"
#include "host/synth/synth.h"
#include "host/train/checkpoint.h"
#include "host/train/init_gaussians.h"
#include "host/train/lidar_planes.h"
#include "host/train/trainer.h"
#include "host/train/training_data.h"
#include "io/gaussian_ply.h"
#include "io/scene.h"
#include "small_training_scene.h"

namespace litgs {
namespace host {
// Readable counters in failure messages.
void PrintTo(const TrainingCounters& c, std::ostream* os) {
  *os << to_json(c).dump();
}
}  // namespace host
namespace {

namespace fs = std::filesystem;

// Thrown from the progress callback: the run stops as if killed after that iteration's checkpoint.
struct Interrupted {};

bool same_bits(const std::vector<float>& a, const std::vector<float>& b) {
  return a.size() == b.size() && std::memcmp(a.data(), b.data(), a.size() * sizeof(float)) == 0;
}

nlohmann::json read_json(const fs::path& path) {
  std::ifstream in(path);
  return nlohmann::json::parse(in);
}

class TrainResumeTest : public testing::SmallTrainingSceneTest {
 protected:
  static void SetUpTestSuite() { set_up_scene("litgs-train-resume"); }

  // 40 iterations, a checkpoint and an evaluation every 10, refinement at 20 and 30.
  static host::TrainOptions options() {
    host::TrainOptions o;
    o.strategy = "adc";  // written for ADC, train's default before it became MCMC
    o.iterations = 40;
    o.sh_degree = 1;
    o.sh_degree_every = 20;
    o.densify_from = 10;
    o.densify_every = 10;
    o.opacity_reset_every = 1000;
    o.eval_every = 10;
    o.checkpoint_every = 10;
    o.progress_every = 1;
    return o;
  }

  // Trains into root_/name; with `stop_after` > 0 the run is interrupted after that iteration (its checkpoint
  // written, nothing else). `notes` receives the trainer's notices.
  host::TrainReport run(const host::TrainOptions& o, const std::string& name, uint32_t stop_after = 0,
                        const kernels::GaussianModel* init = nullptr,
                        std::vector<std::string>* notes = nullptr) {
    return host::train(
        context(), *data_, init ? *init : *initial_, planes_, o, root_ / name,
        [&](const host::TrainProgress& p) {
          if (p.iteration == stop_after) throw Interrupted{};
        },
        nullptr,
        [&](const std::string& line) {
          if (notes) notes->push_back(line);
        });
  }
  // Trains until `stop_after`, interrupted there, then resumes with `resumed` options in the same directory.
  host::TrainReport interrupted_then_resumed(const host::TrainOptions& o, const host::TrainOptions& resumed,
                                             const std::string& name, uint32_t stop_after,
                                             const kernels::GaussianModel* init = nullptr,
                                             std::vector<std::string>* notes = nullptr) {
    EXPECT_THROW(run(o, name, stop_after, init), Interrupted);
    EXPECT_FALSE(fs::exists(root_ / name / "point_cloud.ply")) << "the interrupted run wrote no outputs";
    auto r = resumed;
    r.resume = true;
    return run(r, name, 0, init, notes);
  }

  static fs::path out(const std::string& name) { return root_ / name; }
};

// Everything in metrics.json but the timings must match between an uninterrupted run and a resumed one.
nlohmann::json without_timings(nlohmann::json j) {
  for (const char* k : {"wall_s", "ms_per_iteration", "kernel_ms_per_iteration", "peak_device_bytes",
                        "resumes", "start_iteration"})
    j.erase(k);
  return j;
}

TEST_F(TrainResumeTest, DeterministicResumeIsBitIdenticalAndKeepsEvaluationsAndCounters) {
  // One Gaussian with a NaN mean: the projection culls it in every training render and Adam skips its x until
  // the refinement at 20 prunes it, so the counters before the checkpoint are not zero and must survive it.
  kernels::GaussianModel init = *initial_;
  init.means[0] = std::numeric_limits<float>::quiet_NaN();
  auto o = options();
  o.deterministic = true;
  const host::TrainReport straight = run(o, "det_straight", 0, &init);
  const host::TrainReport resumed = interrupted_then_resumed(o, o, "det_resumed", 20, &init);

  const auto a = io::read_gaussian_ply(out("det_straight") / "point_cloud.ply");
  const auto b = io::read_gaussian_ply(out("det_resumed") / "point_cloud.ply");
  ASSERT_EQ(a.size(), b.size());
  for (const auto member :
       {&kernels::GaussianModel::means, &kernels::GaussianModel::log_scales, &kernels::GaussianModel::quats,
        &kernels::GaussianModel::opacity_logits, &kernels::GaussianModel::sh})
    EXPECT_TRUE(same_bits(a.*member, b.*member));

  // The counters of the first 20 iterations come through the checkpoint.
  EXPECT_EQ(straight.counters.culled_nonfinite, 20u) << "iterations 1..20 rendered the NaN Gaussian";
  EXPECT_EQ(straight.counters.adam_nonfinite_skips[kernels::kMeans], 20u);
  EXPECT_EQ(straight.counters.pruned_nonfinite, 1u);
  EXPECT_EQ(resumed.counters, straight.counters);

  const auto ja = read_json(out("det_straight") / "metrics.json");
  const auto jb = read_json(out("det_resumed") / "metrics.json");
  EXPECT_EQ(without_timings(ja), without_timings(jb)) << ja.dump(1) << "\n" << jb.dump(1);
  ASSERT_EQ(jb["evaluations"].size(), 4u) << "10, 20 from the checkpoint, 30, 40 after the resume";
  EXPECT_EQ(jb["evaluations"][0]["iteration"], 10);
  EXPECT_EQ(jb["counters"]["culled_nonfinite"], 20);
  EXPECT_EQ(jb["counters"]["adam_nonfinite_skips"]["means"], 20);
  EXPECT_EQ(jb["start_iteration"], 20);
  ASSERT_EQ(jb["resumes"].size(), 1u);
  EXPECT_EQ(jb["resumes"][0]["from_iteration"], 20);
  EXPECT_EQ(jb["resumes"][0]["options_checked"], true);
  EXPECT_TRUE(ja["resumes"].empty());
}

TEST_F(TrainResumeTest, FloatAtomicsResumeReachesTheSameQuality) {
  // Float atomics sum gradients in a varying order, so a resumed run is another sample of the same training,
  // not the same bits. Measured on this scene (lavapipe, 16 pairs of runs): without refinement, held-out PSNR
  // of resumed and uninterrupted runs agree within 1e-3 dB, while a resume that lost the Adam moments is off
  // by 0.16 dB and one that restarted from the initial model by 2 dB; with refinement at 20 and 30, Gaussians
  // near the densification threshold flip with the summation order and any two runs, resumed or not, spread
  // by up to 0.033 dB. The tolerances: 0.05 dB, and 0.2 dB with refinement.
  auto o = options();
  o.densify_from = 1000;  // no refinement
  const host::TrainReport straight = run(o, "atomic_straight");
  const host::TrainReport resumed = interrupted_then_resumed(o, o, "atomic_resumed", 20);
  EXPECT_NEAR(resumed.final_eval.psnr_db, straight.final_eval.psnr_db, 0.05);
  EXPECT_NEAR(resumed.final_eval.ssim, straight.final_eval.ssim, 0.005);
  EXPECT_GT(straight.final_eval.psnr_db, straight.evals[1].psnr_db + 1.0)
      << "iterations 21..40 gain more than 1 dB here, so a resume that lost the checkpoint's model would "
         "show";

  auto refined = options();
  const host::TrainReport straight_refined = run(refined, "atomic_refined_straight");
  const host::TrainReport resumed_refined =
      interrupted_then_resumed(refined, refined, "atomic_refined_resumed", 20);
  EXPECT_NEAR(resumed_refined.final_eval.psnr_db, straight_refined.final_eval.psnr_db, 0.2);
  EXPECT_NEAR(resumed_refined.final_eval.ssim, straight_refined.final_eval.ssim, 0.02);
}

TEST_F(TrainResumeTest, ChangedOptionsAreRefusedNamingEachWithBothValues) {
  auto o = options();
  o.deterministic = true;
  EXPECT_THROW(run(o, "refused", 10), Interrupted);
  auto changed = o;
  changed.resume = true;
  changed.lambda_geo = 0.3;
  changed.seed = 7;
  changed.deterministic = false;
  try {
    run(changed, "refused");
    FAIL() << "a resume with other options ran";
  } catch (const std::invalid_argument& e) {
    const std::string m = e.what();
    for (const char* expected :
         {"iter_10.ckpt", "train --resume refused", "--lambda-geo: checkpoint 0.6, now 0.3",
          "--seed: checkpoint 0, now 7", "--deterministic: checkpoint true, now false"})
      EXPECT_NE(m.find(expected), std::string::npos) << "'" << expected << "' missing from:\n" << m;
  }
  EXPECT_FALSE(fs::exists(out("refused") / "point_cloud.ply"));
  EXPECT_FALSE(fs::exists(out("refused") / "checkpoints" / "iter_20.ckpt")) << "nothing ran";
}

TEST_F(TrainResumeTest, ExtendingARunIsAllowedNotedAndKeepsItsEvaluations) {
  auto o = options();
  o.iterations = 20;
  run(o, "extended");  // a complete run of 20, its last checkpoint at 20
  auto more = o;
  more.iterations = 30;
  more.eval_every = 5;
  more.resume = true;
  std::vector<std::string> notes;
  const host::TrainReport r = run(more, "extended", 0, nullptr, &notes);
  std::string all;
  for (const auto& n : notes) all += n + "\n";
  EXPECT_NE(all.find("--iterations: checkpoint 20, now 30: the run is extended"), std::string::npos) << all;
  EXPECT_NE(all.find("--eval-every: checkpoint 10, now 5"), std::string::npos) << all;
  std::vector<uint32_t> at;
  for (const auto& e : r.evals) at.push_back(e.iteration);
  EXPECT_EQ(at, (std::vector<uint32_t>{10, 20, 25, 30})) << "the first run's 10 and 20 (its final) are kept";
  // Fewer iterations than the checkpoint has done: refused.
  auto fewer = more;
  fewer.iterations = 25;
  EXPECT_THROW(run(fewer, "extended"), std::invalid_argument);
}

TEST_F(TrainResumeTest, FormatOneCheckpointIsResumedWithAWarning) {
  auto o = options();
  o.deterministic = true;
  EXPECT_THROW(run(o, "v1", 20), Interrupted);
  // Rewrite the checkpoint at 20 as format 1: magic LITGSCK1, no run record (and no level state, format 3's
  // last array, here empty: its 8-byte count) after the state.
  const fs::path ckpt = out("v1") / "checkpoints" / "iter_20.ckpt";
  std::vector<char> bytes;
  {
    std::ifstream in(ckpt, std::ios::binary);
    bytes.assign(std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>());
  }
  const std::string record = to_json(host::read_checkpoint(ckpt).record).dump();
  ASSERT_EQ(std::string(bytes.end() - 8, bytes.end()), std::string(8, '\0'));
  bytes.resize(bytes.size() - 8);
  ASSERT_EQ(std::string(bytes.end() - static_cast<long>(record.size()), bytes.end()), record);
  bytes.resize(bytes.size() - record.size() - 8);
  bytes[7] = '1';
  std::ofstream(ckpt, std::ios::binary | std::ios::trunc)
      .write(bytes.data(), static_cast<std::streamsize>(bytes.size()));
  fs::remove(out("v1") / "checkpoints" / "iter_10.ckpt");

  auto r = o;
  r.resume = true;
  r.seed = 9;  // not noticed: format 1 stores no options
  std::vector<std::string> notes;
  const host::TrainReport report = run(r, "v1", 0, nullptr, &notes);
  std::string all;
  for (const auto& n : notes) all += n + "\n";
  EXPECT_NE(all.find("warning"), std::string::npos) << all;
  EXPECT_NE(all.find("predates stored options"), std::string::npos) << all;
  ASSERT_EQ(report.resumes.size(), 1u);
  EXPECT_FALSE(report.resumes[0].options_checked);
  std::vector<uint32_t> at;
  for (const auto& e : report.evals) at.push_back(e.iteration);
  EXPECT_EQ(at, (std::vector<uint32_t>{30, 40})) << "evaluations before the format-1 checkpoint are unknown";
  EXPECT_FALSE(read_json(out("v1") / "metrics.json")["resumes"][0]["options_checked"].get<bool>());
}

}  // namespace
}  // namespace litgs
