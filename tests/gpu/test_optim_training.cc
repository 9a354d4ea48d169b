// A training-like smoke test: the device rasterizer, a host L2 loss, and the trainable model's statistics,
// Adam steps and one densification in the middle: the loss must fall.
#include <gtest/gtest.h>

#include <cmath>
#include <random>
#include <vector>

#include "gpu_test.h"
#include "kernels/optim/trainable_gaussians.h"
#include "splat_scenes.h"

namespace litgs::kernels {
namespace {

class TrainingSmokeTest : public testing::GpuTest {};

TEST_F(TrainingSmokeTest, FiftyAdamStepsReduceAnImageLoss) {
  const uint32_t W = 64, H = 48;
  SplatCamera camera = testing::camera_looking_down_z(W, H);
  camera.sh_degree = 1;
  const GaussianModel target_model = testing::random_scene(150, 1, 1, 31);
  Rasterizer raster(context(), 1);
  std::vector<float> target;
  {
    DeviceGaussians target_gaussians(context(), target_model);
    raster.forward(target_gaussians, camera);
    target = raster.download_images().image;
  }
  GaussianModel start = target_model;
  std::mt19937 rng(5);
  std::normal_distribution<float> normal(0.0f, 1.0f);
  for (auto& x : start.means) x += 0.05f * normal(rng);
  for (size_t i = 0; i < start.size(); ++i) {
    start.sh[i * start.sh_coeffs()] += 0.3f * normal(rng);
    start.opacity_logits[i] += 0.5f * normal(rng);
  }
  TrainableGaussians model(context(), start);
  const AdamOptions& adam = model.adam_options();
  const float extent = 5.0f;
  const size_t pixels = size_t{W} * H;
  std::vector<double> losses;
  DensifyReport densified;
  for (uint32_t step = 1; step <= 50; ++step) {
    raster.forward(model.gaussians(), camera);
    const std::vector<float> image = raster.download_images().image;
    std::vector<float> grad(pixels);
    double loss = 0;
    for (size_t p = 0; p < pixels; ++p) {
      const double r = double{image[p]} - target[p];
      loss += r * r / pixels;
      grad[p] = static_cast<float>(2.0 * r / pixels);
    }
    losses.push_back(loss);
    const Rasterizer::DeviceUpstream up = raster.upstream_buffers();
    const_cast<engine::Buffer*>(up.image)->upload(grad.data(), grad.size() * sizeof(float));
    engine::Sequence s(context());
    s.fill(*up.depth, 0u, pixels * 4);
    s.fill(*up.alpha, 0u, pixels * 4);
    const Rasterizer::DeviceGrads grads = raster.record_backward(s);
    model.record_accumulate_stats(s, grads, *raster.device_outputs().rects, camera);
    model.record_adam_step(s, grads, adam.rates(step - 1, 50, extent), step);
    s.submit_and_wait();
    if (step == 25) {
      DensifyOptions o;
      o.grad_threshold = 1e-6f;  // this tiny image's gradients are small: force some densification
      densified = model.densify_and_prune(o, extent, step);
    }
  }
  const GaussianModel final_model = model.download();
  for (float x : final_model.means) ASSERT_TRUE(std::isfinite(x));
  for (uint32_t c : model.nonfinite_grad_counts()) EXPECT_EQ(c, 0u);
  EXPECT_GT(densified.cloned + densified.split, 0u) << densified.to_string();
  EXPECT_EQ(final_model.size(), densified.after);
  for (size_t k = 0; k < losses.size(); k += 5) std::printf("step %zu loss %.6g\n", k + 1, losses[k]);
  std::printf("loss %.6g -> %.6g (%s)\n", losses.front(), losses.back(), densified.to_string().c_str());
  // Falls before the densification, and again after it (3DGS's split children keep the parent's opacity, so
  // the image darkens/brightens where they overlap: the loss jumps at step 26, then falls).
  EXPECT_LT(losses[24], 0.5 * losses[0]);
  EXPECT_LT(losses.back(), 0.7 * losses[25]);
}

}  // namespace
}  // namespace litgs::kernels
