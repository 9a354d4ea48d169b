// CPU tests of the level model's double reference (kernels/level/level_reference.h) against central finite
// differences: the apply's derivatives (image, log-gain, offset, vignetting) and the step's regularizer
// gradient; and Adam's first step and the clamps.
#include <gtest/gtest.h>

#include <cmath>
#include <limits>
#include <random>

#include "kernels/level/level_reference.h"

namespace litgs::kernels {
namespace {

struct Problem {
  LevelGeometry geometry{9, 7, 2, 4.1f, 3.3f};
  std::vector<float> image, target, weight;
};

Problem make_problem(uint32_t seed) {
  Problem p;
  std::mt19937 rng(seed);
  std::uniform_real_distribution<float> u(0.0f, 1.0f);
  const size_t n = size_t{p.geometry.channels} * p.geometry.width * p.geometry.height;
  for (size_t i = 0; i < n; ++i) {
    p.image.push_back(u(rng));
    p.target.push_back(u(rng));
    p.weight.push_back(0.5f + u(rng));
  }
  return p;
}

// L = sum w (x' - y)^2 / 2, smooth in every parameter; its dL/dx' is w (x' - y).
double loss(const Problem& p, const std::vector<float>& image, const LevelValues& v) {
  const std::vector<double> x = level_apply_reference(image, p.geometry, v, true);
  double l = 0;
  for (size_t i = 0; i < x.size(); ++i) l += 0.5 * p.weight[i] * (x[i] - p.target[i]) * (x[i] - p.target[i]);
  return l;
}

TEST(LevelReferenceTest, BackwardMatchesFiniteDifferences) {
  const Problem p = make_problem(3);
  const LevelValues v{0.3, -0.12, 0.2, -0.15};
  const std::vector<double> x = level_apply_reference(p.image, p.geometry, v, true);
  std::vector<float> G(x.size());
  for (size_t i = 0; i < x.size(); ++i) G[i] = static_cast<float>(p.weight[i] * (x[i] - p.target[i]));
  // The reference takes G in float, as the device does: compare with the loss of the same rounding.
  const LevelBackwardReference b = level_backward_reference(p.image, G, p.geometry, v, true);
  const double h = 1e-6;
  double* fields[4] = {nullptr, nullptr, nullptr, nullptr};
  for (int k = 0; k < 4; ++k) {
    LevelValues a = v, c = v;
    fields[0] = &a.log_gain, fields[1] = &a.offset, fields[2] = &a.k1, fields[3] = &a.k2;
    *fields[k] += h;
    fields[0] = &c.log_gain, fields[1] = &c.offset, fields[2] = &c.k1, fields[3] = &c.k2;
    *fields[k] -= h;
    const double fd = (loss(p, p.image, a) - loss(p, p.image, c)) / (2 * h);
    EXPECT_NEAR(b.grad[k], fd, 1e-5 * (1 + std::abs(fd))) << "parameter " << k;
  }
  for (size_t e : {size_t{0}, size_t{17}, size_t{62}, size_t{125}}) {
    std::vector<float> a = p.image, c = p.image;
    const float hf = 1e-3f;  // a float step: the image is float
    a[e] += hf, c[e] -= hf;
    const double step = static_cast<double>(a[e]) - static_cast<double>(c[e]);
    const double fd = (loss(p, a, v) - loss(p, c, v)) / step;
    EXPECT_NEAR(b.grad_image[e], fd, 1e-5 * (1 + std::abs(fd))) << "element " << e;
  }
}

TEST(LevelReferenceTest, WithoutVignettingTheFactorIsOneAndItsGradientZero) {
  const Problem p = make_problem(4);
  const LevelValues v{-0.2, 0.05, 0.3, 0.3};  // k1, k2 ignored
  const std::vector<double> x = level_apply_reference(p.image, p.geometry, v, false);
  for (size_t i = 0; i < x.size(); ++i) EXPECT_NEAR(x[i], std::exp(-0.2) * p.image[i] + 0.05, 1e-12);
  const LevelBackwardReference b = level_backward_reference(p.image, p.weight, p.geometry, v, false);
  EXPECT_EQ(b.grad[2], 0.0);
  EXPECT_EQ(b.grad[3], 0.0);
}

TEST(LevelReferenceTest, StepGradientIsTheRegularizersFiniteDifference) {
  const uint32_t frames = 5;
  std::vector<double> s((frames + 1) * LEVEL_STRIDE, 0.0);
  std::mt19937 rng(9);
  std::uniform_real_distribution<double> u(-0.5, 0.5);
  for (uint32_t f = 0; f <= frames; ++f) s[f * LEVEL_STRIDE] = u(rng), s[f * LEVEL_STRIDE + 1] = u(rng);
  LevelStep step;
  step.frame = 2;
  step.prev = 1;
  step.next = 4;  // a neighbour need not be adjacent (held-out frames in between)
  step.lambda_identity = 0.3f;
  step.lambda_smooth = 0.7f;
  const std::array<double, 4> data{0.1, -0.2, 0.3, 0.05};
  const std::array<double, 4> g = level_step_gradient_reference(s, frames, data, step);
  const std::vector<std::array<uint32_t, 2>> pairs = {{2, 1}, {2, 4}};
  const size_t index[4] = {2 * LEVEL_STRIDE, 2 * LEVEL_STRIDE + 1, frames * LEVEL_STRIDE,
                           frames * LEVEL_STRIDE + 1};
  for (int k = 0; k < 4; ++k) {
    const double h = 1e-6;
    std::vector<double> a = s, c = s;
    a[index[k]] += h, c[index[k]] -= h;
    const double fd = (level_regularizer_reference(a, frames, true, 0.3, 0.7, pairs) -
                       level_regularizer_reference(c, frames, true, 0.3, 0.7, pairs)) /
                      (2 * h);
    EXPECT_NEAR(g[k] - data[k], fd, 1e-6) << "parameter " << k;
  }
}

TEST(LevelReferenceTest, FirstAdamStepMovesEachParameterByItsRateAgainstTheGradient) {
  const uint32_t frames = 3;
  std::vector<double> s((frames + 1) * LEVEL_STRIDE, 0.0);
  LevelStep step;
  step.frame = 1;
  step.lr_log_gain = 0.01f;
  step.lr_offset = 0.02f;
  step.lr_vignetting = 0.003f;
  level_step_reference(s, frames, true, {2.0, -3.0, 0.5, -0.25}, step);
  EXPECT_NEAR(s[LEVEL_STRIDE], -0.01, 1e-9);  // bias-corrected first step: lr * sign(g)
  EXPECT_NEAR(s[LEVEL_STRIDE + 1], 0.02, 1e-9);
  EXPECT_NEAR(s[frames * LEVEL_STRIDE], -0.003, 1e-9);
  EXPECT_NEAR(s[frames * LEVEL_STRIDE + 1], 0.003, 1e-9);
  EXPECT_EQ(s[LEVEL_STRIDE + LEVEL_STEPS], 1.0);  // no frame marked trained: nothing re-centred
  EXPECT_EQ(s[0], 0.0);                           // other frames untouched
  EXPECT_EQ(s[2 * LEVEL_STRIDE], 0.0);
}

TEST(LevelReferenceTest, RecentresTheTrainedFramesOnTheirMean) {
  const uint32_t frames = 4;
  std::vector<double> s((frames + 1) * LEVEL_STRIDE, 0.0);
  const double lg[] = {0.2, -0.1, 9.0, 0.5}, o[] = {0.3, 0.1, -0.2, 7.0};
  for (uint32_t f = 0; f < frames; ++f) {
    s[f * LEVEL_STRIDE] = lg[f];
    s[f * LEVEL_STRIDE + 1] = o[f];
    s[f * LEVEL_STRIDE + LEVEL_TRAINED] = f == 3 ? 0.0 : 1.0;  // frame 3 held out
  }
  LevelStep step;  // zero rates: only the re-centring acts
  step.frame = 1;
  level_step_reference(s, frames, false, {0, 0, 0, 0}, step);
  // Frame 2's log-gain is clamped to the limit before the mean: (0.2 - 0.1 + 4) / 3.
  const double mean_lg = (0.2 - 0.1 + LEVEL_LOG_GAIN_LIMIT) / 3, mean_o = (0.3 + 0.1 - 0.2) / 3;
  EXPECT_NEAR(s[0], 0.2 - mean_lg, 1e-12);
  EXPECT_NEAR(s[2 * LEVEL_STRIDE], LEVEL_LOG_GAIN_LIMIT - mean_lg, 1e-12);
  EXPECT_NEAR(s[LEVEL_STRIDE + 1], 0.1 - mean_o, 1e-12);
  EXPECT_EQ(s[3 * LEVEL_STRIDE], 0.5);  // held out: untouched
  EXPECT_EQ(s[3 * LEVEL_STRIDE + 1], 7.0);
}

TEST(LevelReferenceTest, ClampsLogGainAndVignettingAndSkipsNonFiniteRows) {
  const uint32_t frames = 2;
  std::vector<double> s((frames + 1) * LEVEL_STRIDE, 0.0);
  s[0] = -LEVEL_LOG_GAIN_LIMIT;
  s[frames * LEVEL_STRIDE] = LEVEL_VIGNETTING_LIMIT;
  LevelStep step;
  step.lr_log_gain = step.lr_offset = step.lr_vignetting = 0.5f;
  level_step_reference(s, frames, true, {1.0, 0.0, -1.0, 0.0}, step);
  EXPECT_EQ(s[0], -LEVEL_LOG_GAIN_LIMIT);
  EXPECT_EQ(s[frames * LEVEL_STRIDE], LEVEL_VIGNETTING_LIMIT);
  const std::vector<double> before = s;
  level_step_reference(s, frames, true, {std::numeric_limits<double>::quiet_NaN(), 0.0, 0.0, 0.0}, step);
  for (size_t i = 0; i < LEVEL_STRIDE; ++i) EXPECT_EQ(s[i], before[i]);
  EXPECT_EQ(s[frames * LEVEL_STRIDE + LEVEL_SKIPS], 1.0);
}

}  // namespace
}  // namespace litgs::kernels
