// A training-like smoke test: the device rasterizer, a host L2 loss, and the trainable model's statistics,
// Adam steps and one densification in the middle: the loss must fall. And the same loop with rows whose
// parameters are not finite: every counter on their way (culled, skipped by Adam, pruned) says exactly how
// many, and the rest trains as if they were not there.
#include <gtest/gtest.h>

#include <cmath>
#include <limits>
#include <random>
#include <vector>

#include "gpu_test.h"
#include "kernels/mcmc/mcmc.h"
#include "kernels/optim/trainable_gaussians.h"
#include "splat_scenes.h"

namespace litgs::kernels {
namespace {

class TrainingSmokeTest : public testing::GpuTest {
 protected:
  // The image the model renders from the camera: the target the smoke tests fit.
  std::vector<float> render(const GaussianModel& model, const SplatCamera& camera) {
    Rasterizer raster(context(), model.channels);
    DeviceGaussians gaussians(context(), model);
    raster.forward(gaussians, camera);
    return raster.download_images().image;
  }
};

// The target model with its means, colours and opacities disturbed (seeded): where training starts.
GaussianModel disturbed(const GaussianModel& target) {
  GaussianModel start = target;
  std::mt19937 rng(5);
  std::normal_distribution<float> normal(0.0f, 1.0f);
  for (auto& x : start.means) x += 0.05f * normal(rng);
  for (size_t i = 0; i < start.size(); ++i) {
    start.sh[i * start.sh_coeffs()] += 0.3f * normal(rng);
    start.opacity_logits[i] += 0.5f * normal(rng);
  }
  return start;
}

TEST_F(TrainingSmokeTest, FiftyAdamStepsReduceAnImageLoss) {
  const uint32_t W = 64, H = 48;
  SplatCamera camera = testing::camera_looking_down_z(W, H);
  camera.sh_degree = 1;
  const GaussianModel target_model = testing::random_scene(150, 1, 1, 31);
  Rasterizer raster(context(), 1);
  const std::vector<float> target = render(target_model, camera);
  const GaussianModel start = disturbed(target_model);
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

// The smoke test's loop (50 steps, one densification at 25), deterministic, recording every counter.
struct Trace {
  std::vector<double> losses;
  std::vector<uint32_t> culled_nonfinite;  // per step, by the forward
  std::array<uint32_t, kParamGroupCount> adam_skips_at_25{}, adam_skips{};
  DensifyReport densified;
  GaussianModel final_model;
};

Trace train_smoke(engine::Context& ctx, const GaussianModel& start, const std::vector<float>& target,
                  const SplatCamera& camera) {
  const uint32_t W = camera.width, H = camera.height;
  RasterizerOptions ro;
  ro.deterministic = true;
  Rasterizer raster(ctx, 1, ro);
  TrainableGaussians model(ctx, start);
  const AdamOptions& adam = model.adam_options();
  const float extent = 5.0f;
  const size_t pixels = size_t{W} * H;
  Trace t;
  for (uint32_t step = 1; step <= 50; ++step) {
    raster.forward(model.gaussians(), camera);
    const RenderImages<float> out = raster.download_images();
    t.culled_nonfinite.push_back(out.culled_nonfinite);
    std::vector<float> grad(pixels);
    double loss = 0;
    const auto npix = static_cast<double>(pixels);
    for (size_t p = 0; p < pixels; ++p) {
      const double r = double{out.image[p]} - target[p];
      loss += r * r / npix;
      grad[p] = static_cast<float>(2.0 * r / npix);
    }
    t.losses.push_back(loss);
    const Rasterizer::DeviceUpstream up = raster.upstream_buffers();
    const_cast<engine::Buffer*>(up.image)->upload(grad.data(), grad.size() * sizeof(float));
    engine::Sequence s(ctx);
    s.fill(*up.depth, 0u, pixels * 4);
    s.fill(*up.alpha, 0u, pixels * 4);
    const Rasterizer::DeviceGrads grads = raster.record_backward(s);
    model.record_accumulate_stats(s, grads, *raster.device_outputs().rects, camera);
    model.record_adam_step(s, grads, adam.rates(step - 1, 50, extent), step);
    s.submit_and_wait();
    if (step == 25) {
      t.adam_skips_at_25 = model.nonfinite_grad_counts();
      DensifyOptions o;
      o.grad_threshold = 1e-6f;
      t.densified = model.densify_and_prune(o, extent, step);
    }
  }
  t.adam_skips = model.nonfinite_grad_counts();
  t.final_model = model.download();
  return t;
}

// Five rows appended to the smoke test's model, one non-finite parameter each (NaN mean, +Inf log-scale,
// NaN quaternion, NaN opacity, -Inf SH). Each forward culls exactly 5 and renders the rest as without them;
// their gradients are zero, so Adam skips exactly their one non-finite element per group each step (x not
// finite): 25 per group by the densification at 25, which prunes exactly those 5. Appended last, they leave
// every other row's index (on which split sampling depends) unchanged, so the deterministic run with them
// must match the run without them bit for bit: every loss, and the final model. The loss falls by the smoke
// test's factors.
TEST_F(TrainingSmokeTest, NonFiniteRowsAreCountedSkippedAndPrunedWhileTheRestTrains) {
  const uint32_t W = 64, H = 48;
  SplatCamera camera = testing::camera_looking_down_z(W, H);
  camera.sh_degree = 1;
  const GaussianModel target_model = testing::random_scene(150, 1, 1, 31);
  const std::vector<float> target = render(target_model, camera);
  const GaussianModel clean = disturbed(target_model);
  const float nan = std::numeric_limits<float>::quiet_NaN(), inf = std::numeric_limits<float>::infinity();
  GaussianModel bad = clean;
  const size_t n = clean.size(), k = clean.sh_coeffs();
  bad.resize(n + 5);
  for (size_t r = n; r < n + 5; ++r) {  // visible copies of row 0, then one parameter broken
    for (int a = 0; a < 3; ++a)
      bad.means[3 * r + a] = clean.means[a], bad.log_scales[3 * r + a] = clean.log_scales[a];
    for (int a = 0; a < 4; ++a) bad.quats[4 * r + a] = clean.quats[a];
    bad.opacity_logits[r] = clean.opacity_logits[0];
    for (size_t c = 0; c < k; ++c) bad.sh[r * k + c] = clean.sh[c];
  }
  bad.means[3 * n + 1] = nan;
  bad.log_scales[3 * (n + 1)] = inf;
  bad.quats[4 * (n + 2) + 3] = nan;
  bad.opacity_logits[n + 3] = nan;
  bad.sh[(n + 4) * k + 2] = -inf;
  bad.check();

  const Trace want = train_smoke(context(), clean, target, camera);
  const Trace got = train_smoke(context(), bad, target, camera);
  ASSERT_EQ(got.losses.size(), 50u);
  for (size_t s = 0; s < 50; ++s) {
    EXPECT_EQ(want.culled_nonfinite[s], 0u) << "step " << s + 1;
    EXPECT_EQ(got.culled_nonfinite[s], s < 25 ? 5u : 0u) << "step " << s + 1;
    EXPECT_EQ(got.losses[s], want.losses[s]) << "step " << s + 1;
  }
  for (uint32_t g = 0; g < kParamGroupCount; ++g) {
    EXPECT_EQ(want.adam_skips[g], 0u) << kParamGroupNames[g];
    EXPECT_EQ(got.adam_skips_at_25[g], 25u) << kParamGroupNames[g];
    EXPECT_EQ(got.adam_skips[g], 25u) << kParamGroupNames[g] << ": nothing skipped after the prune";
  }
  EXPECT_EQ(want.densified.pruned_nonfinite, 0u);
  EXPECT_EQ(got.densified.pruned_nonfinite, 5u) << got.densified.to_string();
  EXPECT_EQ(got.densified.pruned(), want.densified.pruned() + 5) << got.densified.to_string();
  EXPECT_EQ(got.densified.cloned, want.densified.cloned);
  EXPECT_EQ(got.densified.split, want.densified.split);
  EXPECT_GT(got.densified.cloned + got.densified.split, 0u);
  ASSERT_EQ(got.final_model.size(), want.final_model.size());
  EXPECT_EQ(got.final_model.means, want.final_model.means);
  EXPECT_EQ(got.final_model.sh, want.final_model.sh);
  EXPECT_EQ(got.final_model.opacity_logits, want.final_model.opacity_logits);
  EXPECT_LT(got.losses[24], 0.5 * got.losses[0]);
  EXPECT_LT(got.losses.back(), 0.7 * got.losses[25]);
}

// A model made for the MCMC strategy keeps no densification statistics (12 bytes per Gaussian): they are not
// among its row arrays, asking for them is a logic error, and its state reports them as zeros.
TEST_F(TrainingSmokeTest, WithoutDensifyStatisticsTheModelHasNoStatisticArrays) {
  const GaussianModel m = testing::random_scene(40, 1, 1, 7);
  TrainableGaussians with(context(), m), without(context(), m, AdamOptions{}, false);
  auto statistics = [](const TrainableGaussians& t) {
    size_t k = 0;
    for (const auto& a : t.row_arrays()) k += a.kind == TrainableGaussians::RowArray::kStatistic;
    return k;
  };
  EXPECT_EQ(statistics(with), 3u);
  EXPECT_EQ(statistics(without), 0u);
  EXPECT_THROW(without.densify_and_prune(DensifyOptions{}, 1.0f, 1), std::logic_error);
  without.grow_rows(m.size() + 5, 0);
  const TrainingState st = without.download_state();
  ASSERT_EQ(st.size(), m.size() + 5);
  ASSERT_EQ(st.grad_accum.size(), st.size());
  for (size_t i = 0; i < st.size(); ++i) {
    EXPECT_EQ(st.grad_accum[i], 0.0f);
    EXPECT_EQ(st.denom[i], 0u);
    EXPECT_EQ(st.max_radius[i], 0.0f);
  }
}

// Training stores no parameter gradient: one fused pass (kernels/optim/gaussian_adam.comp) computes each
// Gaussian's gradients from the rasterizer's rows, adds MCMC's regularizers and steps Adam. Three steps that
// way must match three steps of the separate kernels (project_backward, itself checked against the double
// reference; mcmc_regularize; adam): every parameter and moment of every group, for one and three channels,
// with the active SH degree below the model's and some Gaussians culled.
TEST_F(TrainingSmokeTest, TheFusedStepEqualsTheSeparateBackwardRegularizationAndAdamSteps) {
  for (uint32_t channels : {1u, 3u}) {
    SCOPED_TRACE(channels);
    const uint32_t W = 64, H = 48;
    SplatCamera camera = testing::camera_looking_down_z(W, H);
    camera.sh_degree = 2;  // the model has degree 3: its last band has no gradient
    GaussianModel start = testing::random_scene(300, channels, 3, 17);
    for (size_t i = 0; i < 20; ++i) start.means[3 * i + 2] = -1.0f;  // behind the camera: culled
    TrainableGaussians stored(context(), start), computed(context(), start);
    RasterizerOptions fused_options;
    fused_options.parameter_gradients = false;
    Rasterizer raster_stored(context(), channels), raster_computed(context(), channels, fused_options);
    McmcStrategy mcmc(context());
    McmcOptions mcmc_options;
    mcmc_options.opacity_reg = 0.5f;  // large, so that the regularizers' share of the gradient is seen
    mcmc_options.scale_reg = 0.5f;
    std::mt19937 rng(3);
    std::normal_distribution<float> normal(0.0f, 1e-3f);
    for (uint32_t step = 1; step <= 3; ++step) {
      std::vector<float> grad_image(size_t{W} * H * channels);
      for (float& g : grad_image) g = normal(rng);
      for (auto [model, raster] :
           {std::pair{&stored, &raster_stored}, std::pair{&computed, &raster_computed}}) {
        raster->forward(model->gaussians(), camera);
        const Rasterizer::DeviceUpstream up = raster->upstream_buffers();
        const_cast<engine::Buffer*>(up.image)->upload(grad_image.data(), grad_image.size() * sizeof(float));
        engine::Sequence s(context());
        s.fill(*up.depth, 0u, uint64_t{W} * H * 4);
        s.fill(*up.alpha, 0u, uint64_t{W} * H * 4);
        const Rasterizer::DeviceGrads grads = raster->record_backward(s);
        const LearningRates lr = model->adam_options().rates(step - 1, 3, 5.0f);
        if (raster == &raster_computed) {
          ASSERT_EQ(grads.means, nullptr);
          ASSERT_EQ(grads.sh, nullptr);
          const TrainableGaussians::FusedStep fused{
              raster->device_outputs().rects, camera,
              McmcStrategy::regularization_weights(mcmc_options, static_cast<uint32_t>(model->size()))};
          model->record_adam_step(s, grads, lr, step, &fused);
        } else {
          ASSERT_NE(grads.sh, nullptr);
          mcmc.record_regularization(s, *model, grads, mcmc_options);
          model->record_adam_step(s, grads, lr, step);
        }
        s.submit_and_wait();
      }
    }
    const TrainingState a = stored.download_state(), b = computed.download_state();
    auto expect_close = [](const std::vector<float>& x, const std::vector<float>& y, const char* what) {
      ASSERT_EQ(x.size(), y.size()) << what;
      size_t off = 0;
      for (size_t i = 0; i < x.size(); ++i)
        off += !(std::abs(x[i] - y[i]) <= 1e-6f * (1.0f + std::abs(x[i])));
      EXPECT_EQ(off, 0u) << what << ": values that differ beyond float rounding";
    };
    expect_close(a.model.sh, b.model.sh, "sh");
    expect_close(a.model.means, b.model.means, "means");
    expect_close(a.model.log_scales, b.model.log_scales, "log_scales");
    expect_close(a.model.quats, b.model.quats, "quats");
    expect_close(a.model.opacity_logits, b.model.opacity_logits, "opacity_logits");
    for (uint32_t g = 0; g < kParamGroupCount; ++g) {
      expect_close(a.exp_avg[g], b.exp_avg[g], "exp_avg");
      expect_close(a.exp_avg_sq[g], b.exp_avg_sq[g], "exp_avg_sq");
    }
    // Not vacuous: the steps moved the active bands' coefficients of the Gaussians in view, and none of the
    // last band's (no gradient, zero moments: Adam leaves them).
    size_t active = 0, moved = 0, last_band_moved = 0;
    for (size_t i = 20; i < start.size(); ++i)
      for (size_t k = 0; k < 16; ++k)
        for (size_t c = 0; c < channels; ++c) {
          const size_t j = (i * 16 + k) * channels + c;
          if (k < 9) {
            ++active;
            moved += b.model.sh[j] != start.sh[j];
          } else {
            last_band_moved += b.model.sh[j] != start.sh[j];
          }
        }
    EXPECT_GT(moved, active * 9 / 10);
    EXPECT_EQ(last_band_moved, 0u);
  }
}

}  // namespace
}  // namespace litgs::kernels
