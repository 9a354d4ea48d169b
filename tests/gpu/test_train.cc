// Training end to end on a small synthetic scene (lavapipe, validation on): outputs, exact resume,
// lambda_geo = 0 is photometric-only training, and named stability cases in which no parameter may become
// non-finite and nothing may crash.
#include <gtest/gtest.h>
#include <unistd.h>

#include <algorithm>
#include <cmath>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <nlohmann/json.hpp>
#include <random>

#include "gpu_test.h"
#include "host/synth/synth.h"
#include "host/train/init_gaussians.h"
#include "host/train/lidar_planes.h"
#include "host/train/trainer.h"
#include "host/train/training_data.h"
#include "io/gaussian_ply.h"
#include "io/scene.h"

namespace litgs {
namespace {

namespace fs = std::filesystem;

bool same_bits(const std::vector<float>& a, const std::vector<float>& b) {
  return a.size() == b.size() && std::memcmp(a.data(), b.data(), a.size() * sizeof(float)) == 0;
}

class TrainTest : public testing::GpuTest {
 protected:
  static void SetUpTestSuite() {
    testing::GpuTest::SetUpTestSuite();
    root_ = fs::temp_directory_path() / ("litgs-train-test-" + std::to_string(::getpid()));
    fs::remove_all(root_);
    host::synth::SynthOptions s;
    s.frames = 12;
    s.width = 64;
    s.height = 48;
    s.out = root_ / "scene";
    host::synth::generate_synthetic_scene(s);
    host::TrainingDataOptions d;
    d.holdout_every = 4;
    data_ = new host::TrainingData(host::load_training_data(root_ / "scene", d));
    const io::Scene scene = io::read_scene(root_ / "scene");
    std::vector<Eigen::Vector3d> pts = scene.map->positions;
    planes_ = new host::PlanarMap(host::fit_planes(pts, host::PlaneFitOptions{}));
    std::mt19937 rng(1);
    std::shuffle(pts.begin(), pts.end(), rng);
    pts.resize(3000);
    host::InitOptions init;
    init.sh_degree = 1;
    initial_ = new kernels::GaussianModel(host::init_from_points(pts, *data_, init));
  }
  static void TearDownTestSuite() {
    delete data_;
    delete planes_;
    delete initial_;
    fs::remove_all(root_);
    testing::GpuTest::TearDownTestSuite();
  }

  static host::TrainOptions small_run(uint32_t iterations) {
    host::TrainOptions o;
    o.iterations = iterations;
    o.sh_degree = 1;
    o.sh_degree_every = 20;
    o.densify_from = 10;
    o.densify_every = 10;
    o.opacity_reset_every = 30;
    o.progress_every = 1;
    return o;
  }

  static void expect_finite(const kernels::GaussianModel& m) {
    for (const auto* v : {&m.means, &m.log_scales, &m.quats, &m.opacity_logits, &m.sh})
      for (float x : *v) ASSERT_TRUE(std::isfinite(x));
  }

  // Trains and returns the written model; `losses` receives the loss of every iteration.
  kernels::GaussianModel run(const host::TrainOptions& o, const std::string& name,
                             const host::TrainingData* data = nullptr, const kernels::GaussianModel* init = nullptr,
                             const host::PlanarMap* planes = planes_, std::vector<double>* losses = nullptr) {
    const fs::path out = root_ / name;
    host::train(context(), data ? *data : *data_, init ? *init : *initial_, planes, o, out,
                [&](const host::TrainProgress& p) {
                  if (losses) losses->push_back(p.loss);
                });
    return io::read_gaussian_ply(out / "point_cloud.ply");
  }

  // Trains `o` (deterministic, a checkpoint at 20) straight through, and again resumed from the straight run's
  // checkpoint at 20 as if it had been killed there: every parameter must come out with the same bits.
  void expect_resume_continues_exactly(const host::TrainOptions& o, const std::string& name) {
    const auto straight = run(o, name + "_straight");
    fs::create_directories(root_ / (name + "_resumed") / "checkpoints");
    fs::copy_file(root_ / (name + "_straight") / "checkpoints" / "iter_20.ckpt",
                  root_ / (name + "_resumed") / "checkpoints" / "iter_20.ckpt");
    auto rest = o;
    rest.resume = true;
    const auto resumed = run(rest, name + "_resumed");
    ASSERT_EQ(resumed.size(), straight.size());
    for (const auto member : {&kernels::GaussianModel::means, &kernels::GaussianModel::log_scales,
                              &kernels::GaussianModel::quats, &kernels::GaussianModel::opacity_logits,
                              &kernels::GaussianModel::sh})
      EXPECT_TRUE(same_bits(resumed.*member, straight.*member));
  }

  static inline fs::path root_;
  static inline host::TrainingData* data_ = nullptr;
  static inline host::PlanarMap* planes_ = nullptr;
  static inline kernels::GaussianModel* initial_ = nullptr;
};

TEST_F(TrainTest, TruePosesPlaceTheCamerasAtTheGroundTruth) {
  host::TrainingDataOptions d;
  d.holdout_every = 4;
  d.true_poses = true;
  const host::TrainingData truth = host::load_training_data(root_ / "scene", d);
  const io::Scene scene = io::read_scene(root_ / "scene");
  ASSERT_EQ(truth.views.size(), data_->views.size());
  double moved = 0;
  for (size_t i = 0; i < truth.views.size(); ++i) {
    const auto& c = truth.views[i].camera;
    const glm::dvec3 centre = -glm::transpose(c.R_cam_world) * c.t_cam_world;  // camera centre in the world
    // The synthetic camera's true pose at the frame's time (frozen frames are skipped, so match by time).
    const auto gt = std::find_if(scene.gt->poses.begin(), scene.gt->poses.end(),
                                 [&](const io::TumPose& p) { return std::abs(p.t_s - truth.views[i].t_s) < 1e-6; });
    ASSERT_NE(gt, scene.gt->poses.end());
    for (int k = 0; k < 3; ++k) EXPECT_NEAR(centre[k], gt->p_world[k], 1e-4);
    const auto& e = data_->views[i].camera;
    moved = std::max(moved, glm::length(glm::dvec3(c.t_cam_world) - glm::dvec3(e.t_cam_world)));
  }
  EXPECT_GT(moved, 1e-3) << "the estimated poses drift from the truth, so the two loads differ";
}

TEST_F(TrainTest, TrainsAndWritesOutputs) {
  std::vector<double> losses;
  auto o = small_run(60);
  // Densification and opacity resets raise the loss on purpose (new, unfitted Gaussians); they have their own
  // tests. Here the optimizer alone must bring it down.
  o.opacity_reset_every = 1000;
  o.densify_from = 1000;
  const auto m = run(o, "basic", nullptr, nullptr, planes_, &losses);
  expect_finite(m);
  ASSERT_EQ(losses.size(), 60u);
  double first = 0, last = 0;
  for (int i = 0; i < 10; ++i) first += losses[i], last += losses[losses.size() - 1 - i];
  EXPECT_LT(last, first) << "the loss falls: " << ::testing::PrintToString(losses);
  std::ifstream in(root_ / "basic" / "metrics.json");
  const auto j = nlohmann::json::parse(in);
  for (const char* key : {"iterations", "wall_s", "ms_per_iteration", "gaussians", "peak_device_bytes",
                          "heldout_psnr", "heldout_ssim"})
    EXPECT_TRUE(j.contains(key)) << key;
  // No true planes were given to this run, so no plane RMSE may be claimed.
  EXPECT_FALSE(j.contains("heldout_depth_plane_rmse_m"));
  EXPECT_EQ(j["iterations"], 60);
  EXPECT_EQ(j["gaussians"], m.size());
  EXPECT_GT(j["peak_device_bytes"].get<uint64_t>(), 0u);
}

TEST_F(TrainTest, ResumeContinuesExactly) {
  auto o = small_run(40);
  o.deterministic = true;
  o.checkpoint_every = 20;
  expect_resume_continues_exactly(o, "adc");
}

TEST_F(TrainTest, LambdaZeroIsPhotometricOnly) {
  auto o = small_run(25);
  o.deterministic = true;
  o.lambda_geo = 0;
  const auto with_map = run(o, "lambda0_map", nullptr, nullptr, planes_);
  const auto without = run(o, "lambda0_nomap", nullptr, nullptr, nullptr);
  EXPECT_TRUE(same_bits(with_map.means, without.means));
  EXPECT_TRUE(same_bits(with_map.sh, without.sh));
}

TEST_F(TrainTest, LearningRateHundredTimesTooHigh) {
  auto o = small_run(40);
  o.lr_scale = 100.0f;
  expect_finite(run(o, "lr100"));
}

TEST_F(TrainTest, LossSpike) {
  host::TrainingData spiky = *data_;
  for (auto& v : spiky.views)
    if (!v.heldout) {
      std::fill(v.image.begin(), v.image.end(), 1e6f);  // one view far out of range
      break;
    }
  expect_finite(run(small_run(40), "spike", &spiky));
}

TEST_F(TrainTest, GaussiansDrivenBehindTheCamera) {
  kernels::GaussianModel m = *initial_;
  const auto& c = data_->views[0].camera;
  const glm::dvec3 centre = -glm::transpose(c.R_cam_world) * c.t_cam_world;
  const glm::dvec3 back = glm::transpose(c.R_cam_world) * glm::dvec3(0, 0, -1);
  for (size_t i = 0; i < m.size(); i += 2)
    for (int a = 0; a < 3; ++a) m.means[3 * i + a] = static_cast<float>(centre[a] + 2.0 * back[a]);
  expect_finite(run(small_run(40), "behind", nullptr, &m));
}

TEST_F(TrainTest, ImageWithNoTextureAtAll) {
  host::TrainingData flat = *data_;
  for (auto& v : flat.views) std::fill(v.image.begin(), v.image.end(), 0.5f);
  expect_finite(run(small_run(40), "flat", &flat));
}

TEST_F(TrainTest, ViewWithNoLidarPoints) {
  host::PlanarMap empty;  // no planar point anywhere: every view has valid_count 0
  auto o = small_run(30);
  o.lambda_geo = 0.6;
  expect_finite(run(o, "nolidar", nullptr, nullptr, &empty));
}

TEST_F(TrainTest, GeometricOutlierPruneRemovesGaussiansOffThePlanesAndCanBeTurnedOff) {
  // Every 10th Gaussian moved 30 cm towards the first camera: off its wall by far more than the robust
  // bound, yet near enough to its map points to be claimed by their plane. Not all are claimed: those whose
  // nearest map point is not planar (corners, clutter) or that slid along a wall seen edge-on stay (a quarter
  // of them are pruned in this scene).
  kernels::GaussianModel m = *initial_;
  const auto& c = data_->views[0].camera;
  const glm::dvec3 towards_camera = glm::transpose(c.R_cam_world) * glm::dvec3(0, 0, -1);
  size_t moved = 0;
  for (size_t i = 0; i < m.size(); i += 10, ++moved)
    for (int a = 0; a < 3; ++a) m.means[3 * i + a] += static_cast<float>(0.3 * towards_camera[a]);
  auto o = small_run(21);
  o.lambda_geo = 0.6;
  o.opacity_reset_every = 1000;
  const host::TrainReport pruned = host::train(context(), *data_, m, planes_, o, root_ / "plane_prune");
  EXPECT_GT(pruned.plane_pruned, moved / 8) << "of " << moved << " moved Gaussians";
  o.plane_prune_k = 0;
  const host::TrainReport kept = host::train(context(), *data_, m, planes_, o, root_ / "plane_prune_off");
  EXPECT_EQ(kept.plane_pruned, 0u);
  o.plane_prune_k = -1;
  EXPECT_THROW(o.check(), std::invalid_argument);
}

TEST_F(TrainTest, NoRefinementOnTheLastIteration) {
  // Everything wants to densify, and 30 is a refinement step: stopping at 29 or at 30 must give the same
  // model size, as a split at the last step would write unfitted children.
  auto o = small_run(29);
  o.densify_grad_threshold = 1e-7f;
  const size_t at_29 = run(o, "last_29").size();
  o.iterations = 30;
  const size_t at_30 = run(o, "last_30").size();
  EXPECT_GT(at_29, initial_->size()) << "the refinement at 20 densified";
  EXPECT_EQ(at_30, at_29);
}

TEST_F(TrainTest, DensificationHitsTheCap) {
  auto o = small_run(60);
  o.max_gaussians = static_cast<uint32_t>(initial_->size() + 50);
  o.densify_grad_threshold = 1e-7f;  // everything wants to densify
  const auto m = run(o, "cap");
  expect_finite(m);
  EXPECT_LE(m.size(), initial_->size() + 50);
}

}  // namespace
}  // namespace litgs

namespace litgs {
namespace {

// The MCMC strategy end to end: the model grows to its budget and never beyond, the loss falls, nothing
// becomes non-finite, and a resume continues exactly (relocation and noise depend only on seed, step, row).
class TrainMcmcTest : public TrainTest {};

TEST_F(TrainMcmcTest, StaysWithinTheBudgetAndLearns) {
  std::vector<double> losses;
  auto o = small_run(60);
  o.strategy = "mcmc";
  o.max_gaussians = static_cast<uint32_t>(initial_->size() + 400);
  o.mcmc_growth = 0.1f;
  const auto m = run(o, "mcmc", nullptr, nullptr, planes_, &losses);
  expect_finite(m);
  EXPECT_EQ(m.size(), initial_->size() + 400) << "5 refinements of +10% reach the budget and stop there";
  double first = 0, last = 0;
  for (int i = 0; i < 10; ++i) first += losses[i], last += losses[losses.size() - 1 - i];
  EXPECT_LT(last, first) << ::testing::PrintToString(losses);
}

TEST_F(TrainMcmcTest, ResumeContinuesExactly) {
  auto o = small_run(40);
  o.strategy = "mcmc";
  o.deterministic = true;
  o.checkpoint_every = 20;
  o.max_gaussians = static_cast<uint32_t>(initial_->size() + 300);
  expect_resume_continues_exactly(o, "mcmc");
}

}  // namespace
}  // namespace litgs
