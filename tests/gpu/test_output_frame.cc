// The frame of what train writes and render reads, end to end (lavapipe, validation on): on a scene recentred
// far from the origin, point_cloud.ply lies in the original world frame (its header says so), and
// `litgs-engine render --scene --time` at a held-out frame of poses.txt draws the image the trainer's own
// evaluation drew of that view; with --recentred-output the PLY is the trainer's model bit for bit and the
// render matches exactly.
#include <gtest/gtest.h>
#include <unistd.h>

#include <Eigen/Geometry>
#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <limits>
#include <nlohmann/json.hpp>
#include <random>

#include "engine_cli.h"
#include "gpu_test.h"
#include "host/synth/synth.h"
#include "host/train/checkpoint.h"
#include "host/train/evaluation.h"
#include "host/train/init_gaussians.h"
#include "host/train/lidar_planes.h"
#include "host/train/output_frame.h"
#include "host/train/trainer.h"
#include "host/train/training_data.h"
#include "io/gaussian_ply.h"
#include "io/image.h"
#include "io/scene.h"
#include "io/scene_yaml.h"
#include "kernels/optim/trainable_gaussians.h"
#include "small_training_scene.h"
#include "splat_scenes.h"

namespace litgs {
namespace {

namespace fs = std::filesystem;

using testing::CommandResult;
using testing::run_engine;

// A render as render --bit-depth 16 writes it: [0, 1] clamped, times 65535, rounded.
std::vector<int> quantized(const std::vector<float>& image) {
  std::vector<int> q(image.size());
  for (size_t i = 0; i < image.size(); ++i)
    q[i] = static_cast<int>(std::lround(std::clamp(static_cast<double>(image[i]), 0.0, 1.0) * 65535.0));
  return q;
}

struct Difference {
  int max = 0;
  double mean = 0;
  size_t above_16 = 0;  // pixels that differ by more than 16 / 65535
};
Difference difference(const std::vector<int>& a, const io::Image& b) {
  EXPECT_EQ(a.size(), b.data.size());
  Difference d;
  for (size_t i = 0; i < std::min(a.size(), b.data.size()); ++i) {
    const int x = std::abs(a[i] - static_cast<int>(b.data[i]));
    d.max = std::max(d.max, x);
    d.mean += x;
    d.above_16 += x > 16;
  }
  d.mean /= static_cast<double>(std::max<size_t>(a.size(), 1));
  return d;
}

class OutputFrameTest : public testing::SmallTrainingSceneTest {
 protected:
  static void SetUpTestSuite() {
    set_up_scene("litgs-output-frame", [](const fs::path& dir) {
      // The synthetic scene as if it had been recentred from a survey frame far from the origin (like DUNR's,
      // near 1000 m): only the stated offset changes, every stored position stays as it is.
      io::SceneConfig config = io::read_scene_yaml(dir / "scene.yaml");
      config.world_offset_m = kOffset;
      io::write_scene_yaml(dir / "scene.yaml", config);
    });
  }

  // 30 iterations (SH degree 1 active from 20, so the evaluation and the PLY use the same degree), refinement
  // at 20, the last checkpoint at 30: the model the trainer evaluated at the end.
  static host::TrainOptions options() {
    host::TrainOptions o;
    o.strategy = "adc";  // written for ADC, train's default before it became MCMC
    o.iterations = 30;
    o.sh_degree = 1;
    o.sh_degree_every = 20;
    o.densify_from = 10;
    o.densify_every = 10;
    o.checkpoint_every = 30;
    return o;
  }

  // The trainer's own final evaluation renders of the held-out views, from the model of the last checkpoint.
  std::vector<kernels::RenderImages<float>> evaluation_renders(const fs::path& out, double* psnr) {
    const host::Checkpoint c = host::read_checkpoint(out / "checkpoints" / "iter_30.ckpt");
    kernels::TrainableGaussians model(context(), c.state);
    kernels::Rasterizer rasterizer(context(), 1);
    const host::TrainOptions o = options();
    host::Evaluator evaluator(*data_, o, nullptr, rasterizer);
    std::vector<kernels::RenderImages<float>> renders;
    *psnr = evaluator.evaluate(model.gaussians(), 30, &renders).psnr_db;
    return renders;
  }

  // The held-out views, in the order of the evaluation's renders.
  static std::vector<uint32_t> heldout() {
    std::vector<uint32_t> v;
    for (uint32_t i = 0; i < data_->views.size(); ++i)
      if (data_->views[i].heldout) v.push_back(i);
    return v;
  }

  static std::string time_of(uint32_t view) {
    char buf[64];
    std::snprintf(buf, sizeof buf, "%.6f", data_->views[view].t_s);
    return buf;
  }

  // A camera file (render --camera) for `view`'s camera, its pose in the scene frame.
  static fs::path camera_file(uint32_t view) {
    const kernels::SplatCamera& c = data_->views[view].camera;
    Eigen::Matrix3d R;
    for (int r = 0; r < 3; ++r)
      for (int k = 0; k < 3; ++k) R(r, k) = c.R_cam_world[k][r];
    const Eigen::Quaterniond q(R);
    const fs::path path = root_ / ("camera_" + std::to_string(view) + ".json");
    const nlohmann::json j = {{"width", c.width},
                              {"height", c.height},
                              {"fx", c.fx},
                              {"fy", c.fy},
                              {"cx", c.cx},
                              {"cy", c.cy},
                              {"q_cam_world", {q.w(), q.x(), q.y(), q.z()}},
                              {"t_cam_world", {c.t_cam_world[0], c.t_cam_world[1], c.t_cam_world[2]}}};
    std::ofstream(path) << j.dump(2);
    return path;
  }

  static inline const Eigen::Vector3d kOffset{1000.25, -2000.5, 30.125};
};

TEST_F(OutputFrameTest, PlyInTheOriginalFrameRendersAtPosesTxtTimesLikeTheEvaluation) {
  const fs::path out = root_ / "original";
  host::train(context(), *data_, *initial_, planes_, options(), out);
  double psnr = 0;
  const auto renders = evaluation_renders(out, &psnr);
  std::ifstream metrics_in(out / "metrics.json");
  const auto metrics = nlohmann::json::parse(metrics_in);
  ASSERT_EQ(metrics["heldout_psnr"].get<double>(), psnr) << "these are the renders the trainer evaluated";
  EXPECT_EQ(metrics["point_cloud_frame"], "original");

  // The PLY: the trainer's means plus the offset, to float precision at 2000 m (half a step: 6.1e-5 m).
  const fs::path ply = out / "point_cloud.ply";
  const kernels::GaussianModel written = io::read_gaussian_ply(ply);
  const host::Checkpoint c = host::read_checkpoint(out / "checkpoints" / "iter_30.ckpt");
  ASSERT_EQ(written.size(), c.state.model.size());
  for (size_t i = 0; i < written.size(); ++i)
    for (int a = 0; a < 3; ++a)
      ASSERT_NEAR(written.means[3 * i + a], c.state.model.means[3 * i + a] + kOffset[a], 6.2e-5) << i;
  const host::ModelFrame frame = host::read_model_frame(ply);
  EXPECT_EQ(frame.world_offset_m, Eigen::Vector3d::Zero());
  ASSERT_TRUE(frame.scene_world_offset_m.has_value());
  EXPECT_EQ(*frame.scene_world_offset_m, kOffset);

  ASSERT_EQ(renders.size(), heldout().size());
  ASSERT_GE(renders.size(), 1u);
  for (size_t k = 0; k < renders.size(); ++k) {
    const uint32_t v = heldout()[k];
    const fs::path png = root_ / ("time_" + std::to_string(k) + ".png");
    const CommandResult r =
        run_engine("render --model " + ply.string() + " --scene " + (root_ / "scene").string() + " --time " +
                   time_of(v) + " --bit-depth 16 --out " + png.string());
    ASSERT_EQ(r.status, 0) << r.output;
    EXPECT_NE(r.output.find("poses in the scene frame"), std::string::npos) << r.output;
    const std::vector<int> expected = quantized(renders[k].image);
    const io::Image image = io::read_image(png);
    ASSERT_EQ(image.width, static_cast<int>(data_->width));
    // The PLY's float means are off the trainer's by up to 6.1e-5 m, a ten-thousandth of a pixel here: the
    // images agree to a few 16-bit steps, except where a Gaussian's alpha sits on the blend's 1/255 cut-off
    // and the shift tips it (measured: max 55 steps at one pixel, mean 0.16).
    const Difference d = difference(expected, image);
    EXPECT_LE(d.mean, 2.0) << "max " << d.max;
    EXPECT_LE(d.above_16, expected.size() / 100) << "max " << d.max;
    EXPECT_LE(d.max, 655) << "1% of the range";
    size_t lit = 0;
    for (int x : expected) lit += x > 655;
    EXPECT_GT(lit, expected.size() / 2) << "the view sees the model";

    // The same camera as a file: the pose is in the scene frame (the PLY's header names the scene).
    const fs::path cam = camera_file(v);
    const fs::path png2 = root_ / ("camera_" + std::to_string(k) + ".png");
    const CommandResult r2 = run_engine("render --model " + ply.string() + " --camera " + cam.string() +
                                        " --bit-depth 16 --out " + png2.string());
    ASSERT_EQ(r2.status, 0) << r2.output;
    const Difference d2 = difference(expected, io::read_image(png2));
    EXPECT_LE(d2.mean, 2.0);
    EXPECT_LE(d2.above_16, expected.size() / 100);

    // Taken as original-world coordinates, the same pose sees none of the model (it lies 2 km away): the
    // frame conversion above is what makes the images agree.
    const fs::path png3 = root_ / ("wrong_" + std::to_string(k) + ".png");
    const CommandResult r3 = run_engine("render --model " + ply.string() + " --camera " + cam.string() +
                                        " --pose-frame original --bit-depth 16 --out " + png3.string());
    ASSERT_EQ(r3.status, 0) << r3.output;
    EXPECT_GT(difference(expected, io::read_image(png3)).mean, 3000.0);
  }
}

TEST_F(OutputFrameTest, RecentredOutputIsTheTrainersModelAndRendersIdentically) {
  const fs::path out = root_ / "recentred";
  host::train(context(), *data_, *initial_, planes_, options(), out);
  // --recentred-output may change on resume: from the last checkpoint nothing is trained, the PLY is
  // rewritten.
  auto o = options();
  o.recentred_output = true;
  o.resume = true;
  host::train(context(), *data_, *initial_, planes_, o, out, {}, nullptr, [](const std::string&) {});
  const fs::path ply = out / "point_cloud.ply";
  const kernels::GaussianModel written = io::read_gaussian_ply(ply);
  const host::Checkpoint c = host::read_checkpoint(out / "checkpoints" / "iter_30.ckpt");
  ASSERT_EQ(written.means.size(), c.state.model.means.size());
  EXPECT_EQ(
      std::memcmp(written.means.data(), c.state.model.means.data(), written.means.size() * sizeof(float)), 0);
  const host::ModelFrame frame = host::read_model_frame(ply);
  EXPECT_EQ(frame.world_offset_m, kOffset);

  double psnr = 0;
  const auto renders = evaluation_renders(out, &psnr);
  ASSERT_EQ(renders.size(), heldout().size());
  const fs::path png = root_ / "recentred.png";
  const CommandResult r =
      run_engine("render --model " + ply.string() + " --scene " + (root_ / "scene").string() + " --time " +
                 time_of(heldout()[0]) + " --bit-depth 16 --out " + png.string());
  ASSERT_EQ(r.status, 0) << r.output;
  EXPECT_EQ(difference(quantized(renders[0].image), io::read_image(png)).max, 0);
}

// render says when Gaussians were culled for non-finite parameters (nothing else would tell), and is silent
// when none were. (Walks cut short are reported the same way; tests/gpu/test_rasterizer_long_lists.cc makes
// lavapipe cut one.)
TEST(RenderCounters, CulledGaussiansAreReported) {
  const fs::path dir = fs::temp_directory_path() / ("litgs-render-counters-" + std::to_string(::getpid()));
  fs::create_directories(dir);
  kernels::GaussianModel m = testing::random_scene(300, 1, 0, 5);
  io::write_gaussian_ply(dir / "clean.ply", m);
  m.log_scales[3 * 7] =
      std::numeric_limits<float>::quiet_NaN();  // (the PLY reader refuses non-finite positions)
  m.opacity_logits[11] = std::numeric_limits<float>::infinity();
  io::write_gaussian_ply(dir / "nan.ply", m);
  const std::string camera = " --pose 1 0 0 0 0 0 0 --intrinsics 48 48 24 20 --width 48 --height 40 --out ";
  const CommandResult bad =
      run_engine("render --model " + (dir / "nan.ply").string() + camera + (dir / "a.png").string());
  ASSERT_EQ(bad.status, 0) << bad.output;
  EXPECT_NE(bad.output.find("render: warning: 2 Gaussians culled for a non-finite parameter"),
            std::string::npos)
      << bad.output;
  const CommandResult good =
      run_engine("render --model " + (dir / "clean.ply").string() + camera + (dir / "b.png").string());
  ASSERT_EQ(good.status, 0) << good.output;
  EXPECT_EQ(good.output.find("warning"), std::string::npos) << good.output;
  fs::remove_all(dir);
}

}  // namespace
}  // namespace litgs
