// The level model's kernels (kernels/level/) against their double-precision reference, validation layer on:
// the apply, the backward (image gradient and the parameters' gradient sums through the step), Adam with
// the regularizers over several steps, and the hard cases (a constant frame, a gain driven toward zero, a
// non-finite gradient). Tolerances (float kernels, double reference):
//   apply and image gradient: 1e-5 relative to the largest value;
//   state after the steps: 1e-5 absolute on values of order 0.1 (Adam steps are lr-sized, lr <= 0.05).
#include <gtest/gtest.h>

#include <cmath>
#include <limits>
#include <random>
#include <vector>

#include "engine/buffer.h"
#include "engine/sequence.h"
#include "gpu_test.h"
#include "kernels/level/level_model.h"
#include "kernels/level/level_reference.h"

namespace litgs {
namespace {

using engine::DeviceArray;
using kernels::LevelGeometry;
using kernels::LevelModel;
using kernels::LevelStep;

std::vector<float> random_values(size_t n, uint32_t seed, float lo, float hi) {
  std::mt19937 rng(seed);
  std::uniform_real_distribution<float> u(lo, hi);
  std::vector<float> v(n);
  for (auto& x : v) x = u(rng);
  return v;
}

class LevelTest : public testing::GpuTest {
 protected:
  // A state with every frame's log-gain and offset and the vignetting set to small random values; frames
  // marked trained where `trained` says so (none when empty).
  static std::vector<float> random_state(uint32_t frames, uint32_t seed,
                                         const std::vector<bool>& trained = {}) {
    std::vector<float> s = trained.empty() ? std::vector<float>((frames + 1) * LEVEL_STRIDE, 0.0f)
                                           : LevelModel::identity_state(trained);
    const std::vector<float> r = random_values(2 * (frames + 1), seed, -0.3f, 0.3f);
    for (uint32_t f = 0; f <= frames; ++f) {
      s[f * LEVEL_STRIDE] = r[2 * f];
      s[f * LEVEL_STRIDE + 1] = r[2 * f + 1];
    }
    return s;
  }

  // One step on the device: apply (returned), then backward and step with dL/dx' = `grad_leveled`;
  // `grad_image` receives dL/dx.
  std::vector<float> device_step(LevelModel& level, const DeviceArray<float>& image,
                                 const std::vector<float>& grad_leveled, const LevelGeometry& g,
                                 const LevelStep& step, std::vector<float>& grad_image) {
    DeviceArray<float> G(context(), "test: grad leveled", grad_leveled.size());
    DeviceArray<float> out(context(), "test: grad image", grad_leveled.size());
    G.upload(grad_leveled);
    level.reserve(grad_leveled.size());
    engine::Sequence s(context());
    level.record_apply(s, image.buffer(), step.frame, g);
    DeviceArray<float> leveled(context(), "test: leveled", grad_leveled.size());
    s.copy(level.leveled(), leveled.buffer(), grad_leveled.size() * sizeof(float));
    s.copy(G.buffer(), level.grad_leveled(), grad_leveled.size() * sizeof(float));
    level.record_backward_step(s, image.buffer(), g, step, out.buffer());
    s.submit_and_wait();
    grad_image = out.download();
    return leveled.download();
  }
};

double max_abs(const std::vector<double>& v) {
  double m = 0;
  for (double x : v) m = std::max(m, std::abs(x));
  return m;
}

// Several steps on changing frames, over several blocks with a partial last one, with and without
// vignetting: the apply, the image gradient and the whole state follow the reference at every step.
TEST_F(LevelTest, StepsMatchReference) {
  for (bool vignetting : {true, false}) {
    SCOPED_TRACE(vignetting ? "vignetting" : "affine");
    const uint32_t frames = 6;
    const LevelGeometry g{160, 67, 2, 81.3f, 30.2f};  // 21,440 elements: 6 blocks, the last partial
    const size_t n = size_t{g.channels} * g.width * g.height;
    const std::vector<float> image_values = random_values(n, 1, 0.0f, 1.0f);
    DeviceArray<float> image(context(), "test: image", n);
    image.upload(image_values);
    const std::vector<bool> trained = {true, true, true, true, false, true};  // frame 4 held out
    LevelModel level(context(), trained, vignetting);
    std::vector<float> state = random_state(frames, 2, trained);
    level.upload_state(state);
    std::vector<double> ref(state.begin(), state.end());
    const uint32_t order[] = {3, 0, 5, 3, 2};  // never 4
    for (uint32_t k = 0; k < 5; ++k) {
      LevelStep step;
      step.frame = order[k];
      step.prev = order[k] > 0 ? static_cast<int>(order[k]) - 1 : -1;
      step.next = order[k] + 2 < frames ? static_cast<int>(order[k]) + 2 : -1;
      step.lr_log_gain = 0.01f, step.lr_offset = 0.02f, step.lr_vignetting = 0.005f;
      step.lambda_identity = 0.05f, step.lambda_smooth = 0.2f;
      // The gradient scale of a mean loss: 1/N per element.
      std::vector<float> G = random_values(n, 10 + k, -1.0f, 1.0f);
      for (float& x : G) x /= static_cast<float>(n);
      std::vector<float> grad_image;
      const std::vector<float> leveled = device_step(level, image, G, g, step, grad_image);

      std::vector<float> ref_state_f(ref.begin(), ref.end());
      const kernels::LevelValues v = kernels::level_values(ref_state_f, step.frame, vignetting);
      const std::vector<double> x = kernels::level_apply_reference(image_values, g, v, vignetting);
      const auto b = kernels::level_backward_reference(image_values, G, g, v, vignetting);
      double apply_err = 0, grad_err = 0;
      for (size_t i = 0; i < n; ++i) {
        apply_err = std::max(apply_err, std::abs(leveled[i] - x[i]));
        grad_err = std::max(grad_err, std::abs(grad_image[i] - b.grad_image[i]));
      }
      EXPECT_LE(apply_err, 1e-5 * max_abs(x)) << "step " << k;
      EXPECT_LE(grad_err, 1e-5 * max_abs(b.grad_image)) << "step " << k;
      kernels::level_step_reference(ref, frames, vignetting, b.grad, step);
      const std::vector<float> device_state = level.download_state();
      for (size_t i = 0; i < ref.size(); ++i)
        ASSERT_NEAR(device_state[i], ref[i], 1e-5 + 1e-5 * std::abs(ref[i]))
            << "step " << k << ", state element " << i;
      if (!vignetting) {
        EXPECT_EQ(device_state[frames * LEVEL_STRIDE], state[frames * LEVEL_STRIDE]);  // untouched
      }
    }
    // The map's level: the trained frames' mean log-gain and offset are 0; the held-out row never moves.
    const std::vector<float> final_state = level.download_state();
    double mean_lg = 0, mean_o = 0;
    for (uint32_t f = 0; f < frames; ++f)
      if (trained[f]) mean_lg += final_state[f * LEVEL_STRIDE], mean_o += final_state[f * LEVEL_STRIDE + 1];
    EXPECT_NEAR(mean_lg, 0.0, 1e-6);
    EXPECT_NEAR(mean_o, 0.0, 1e-6);
    EXPECT_EQ(final_state[4 * LEVEL_STRIDE], state[4 * LEVEL_STRIDE]) << "the held-out row moved";
    EXPECT_EQ(final_state[4 * LEVEL_STRIDE + 1], state[4 * LEVEL_STRIDE + 1]) << "the held-out row moved";
  }
}

TEST_F(LevelTest, IdentityLeavesImageAndGradientBitForBit) {
  // Gain exp(0) = 1, offset 0, v = 1: the apply and the image gradient are exact copies, so a level model at
  // identity with zero rates changes nothing that training computes.
  const LevelGeometry g{33, 17, 1, 16.5f, 8.5f};
  const size_t n = size_t{g.width} * g.height;
  const std::vector<float> values = random_values(n, 5, -2.0f, 3.0f);
  const std::vector<float> G = random_values(n, 6, -1e-3f, 1e-3f);
  DeviceArray<float> image(context(), "test: image", n);
  image.upload(values);
  for (bool vignetting : {false, true}) {
    LevelModel level(context(), {true}, vignetting);
    std::vector<float> grad_image;
    const std::vector<float> leveled = device_step(level, image, G, g, LevelStep{}, grad_image);
    EXPECT_EQ(leveled, values);
    EXPECT_EQ(grad_image, G);
    const std::vector<float> s = level.download_state();
    for (size_t i : {size_t{0}, size_t{1}, size_t{LEVEL_STRIDE}, size_t{LEVEL_STRIDE + 1}})
      EXPECT_EQ(s[i], 0.0f) << "zero rates moved parameter " << i;
  }
}

TEST_F(LevelTest, HardCaseConstantFrameHasNoGradientAndStaysFinite) {
  // A frame whose render matches its constant target exactly: dL/dx' = 0 everywhere. Nothing may move but
  // the regularizers' pull, and nothing may become non-finite (Adam's 0 / (0 + eps)).
  const LevelGeometry g{64, 48, 1, 32.0f, 24.0f};
  const size_t n = size_t{g.width} * g.height;
  DeviceArray<float> image(context(), "test: image", n);
  image.upload(std::vector<float>(n, 0.5f));
  LevelModel level(context(), {true, true}, true);
  LevelStep step;
  step.lr_log_gain = step.lr_offset = step.lr_vignetting = 0.05f;
  std::vector<float> grad_image;
  for (int k = 0; k < 20; ++k) device_step(level, image, std::vector<float>(n, 0.0f), g, step, grad_image);
  const std::vector<float> s = level.download_state();
  for (float x : s) EXPECT_TRUE(std::isfinite(x));
  EXPECT_EQ(s[0], 0.0f);
  EXPECT_EQ(s[1], 0.0f);
  EXPECT_EQ(s[2 * LEVEL_STRIDE + LEVEL_SKIPS], 0.0f);
  for (float x : grad_image) EXPECT_EQ(x, 0.0f);
}

TEST_F(LevelTest, HardCaseGainDrivenTowardZeroStaysPositiveAndRecovers) {
  // A bad initialization (log-gain -30: gain 1e-13) and a gradient that keeps pushing it down: the
  // log-gain is clamped at -LEVEL_LOG_GAIN_LIMIT (gain 0.37 > 0); pushed up again it leaves the clamp.
  const LevelGeometry g{40, 30, 1, 20.0f, 15.0f};
  const size_t n = size_t{g.width} * g.height;
  DeviceArray<float> image(context(), "test: image", n);
  image.upload(random_values(n, 7, 0.2f, 1.0f));
  LevelModel level(context(), {true}, false);
  std::vector<float> s = level.download_state();
  s[0] = -30.0f;
  level.upload_state(s);
  LevelStep step;
  step.lr_log_gain = 0.1f;
  step.center = false;  // a lone frame is its own mean: re-centring would hide the clamp
  std::vector<float> grad_image;
  // dL/dx' > 0 with x > 0: the loss wants a smaller gain.
  for (int k = 0; k < 5; ++k)
    device_step(level, image, std::vector<float>(n, 1.0f / static_cast<float>(n)), g, step, grad_image);
  s = level.download_state();
  EXPECT_EQ(s[0], -static_cast<float>(LEVEL_LOG_GAIN_LIMIT));
  EXPECT_GT(std::exp(s[0]), 0.0f);
  for (float x : grad_image) EXPECT_TRUE(std::isfinite(x) && x > 0.0f);
  for (int k = 0; k < 30; ++k)
    device_step(level, image, std::vector<float>(n, -1.0f / static_cast<float>(n)), g, step, grad_image);
  s = level.download_state();
  EXPECT_GT(s[0], -static_cast<float>(LEVEL_LOG_GAIN_LIMIT) + 1.0f);
}

TEST_F(LevelTest, HardCaseNonFiniteGradientIsSkippedAndCounted) {
  const LevelGeometry g{16, 16, 1, 8.0f, 8.0f};
  const size_t n = size_t{g.width} * g.height;
  DeviceArray<float> image(context(), "test: image", n);
  image.upload(random_values(n, 8, 0.0f, 1.0f));
  LevelModel level(context(), {true, true, true}, false);
  const std::vector<float> before = random_state(3, 9);  // no frame marked trained: no re-centring
  level.upload_state(before);
  std::vector<float> G(n, 0.01f);
  G[37] = std::numeric_limits<float>::quiet_NaN();
  LevelStep step;
  step.frame = 1;
  step.lr_log_gain = step.lr_offset = 0.01f;
  std::vector<float> grad_image;
  device_step(level, image, G, g, step, grad_image);
  const std::vector<float> s = level.download_state();
  for (size_t i = 0; i < 3 * LEVEL_STRIDE; ++i) EXPECT_EQ(s[i], before[i]) << i;
  EXPECT_EQ(s[3 * LEVEL_STRIDE + LEVEL_SKIPS], 1.0f);
}

TEST_F(LevelTest, RefusesBadFramesAndStates) {
  LevelModel level(context(), {true, true}, false);
  EXPECT_THROW(level.upload_state(std::vector<float>(5)), std::invalid_argument);
  DeviceArray<float> image(context(), "test: image", 16);
  engine::Sequence s(context());
  EXPECT_THROW(level.record_apply(s, image.buffer(), 2, LevelGeometry{4, 4, 1, 2, 2}), std::invalid_argument);
  EXPECT_THROW(level.record_apply(s, image.buffer(), 0, LevelGeometry{8, 4, 1, 2, 2}), std::invalid_argument);
  EXPECT_THROW(LevelModel(context(), std::vector<bool>{}, false), std::invalid_argument);
}

}  // namespace
}  // namespace litgs
