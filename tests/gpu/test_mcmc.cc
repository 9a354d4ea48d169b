// The MCMC strategy on the device (kernels/mcmc/) against its CPU reference (mcmc_reference.h): dead rows,
// draws, relocation, growth up to the budget, noise and regularization, and the hard cases.
#include <gtest/gtest.h>

#include <cmath>
#include <cstring>
#include <limits>
#include <random>
#include <set>
#include <vector>

#include "gpu_test.h"
#include "kernels/mcmc/mcmc.h"
#include "kernels/mcmc/mcmc_math.h"
#include "kernels/mcmc/mcmc_reference.h"
#include "kernels/optim/trainable_gaussians.h"
#include "splat_scenes.h"

namespace litgs::kernels {
namespace {

using engine::DeviceArray;
using testing::GpuTest;

class McmcTest : public GpuTest {};

uint32_t bits(float x) {
  uint32_t b;
  std::memcpy(&b, &x, 4);
  return b;
}

float logit(double o) {
  return static_cast<float>(std::log(o / (1.0 - o)));
}

// Random Gaussians, about 15% transparent, three non-finite rows, random moments and statistics.
TrainingState random_state(size_t n, uint32_t seed) {
  TrainingState s = TrainingState::fresh(testing::random_scene(n, 1, 1, seed));
  std::mt19937 rng(seed + 1);
  std::uniform_real_distribution<float> u(0.0f, 1.0f);
  for (size_t i = 0; i < n; ++i) {
    if (u(rng) < 0.15f) s.model.opacity_logits[i] = -7.0f;
    s.grad_accum[i] = u(rng);
    s.denom[i] = 1 + static_cast<uint32_t>(4 * u(rng));
    s.max_radius[i] = 10 * u(rng);
  }
  for (uint32_t g = 0; g < kParamGroupCount; ++g) {
    for (auto& x : s.exp_avg[g]) x = u(rng) - 0.5f;
    for (auto& x : s.exp_avg_sq[g]) x = u(rng);
  }
  s.model.means[3 * 5 + 2] = std::numeric_limits<float>::quiet_NaN();
  s.model.quats[4 * 11] = std::numeric_limits<float>::infinity();
  s.model.opacity_logits[17] = std::numeric_limits<float>::quiet_NaN();
  return s;
}

// `in` with `rows` rows, the added ones zero (what grow_rows gives the strategy).
TrainingState padded(const TrainingState& in, size_t rows) {
  TrainingState out = in;
  out.model.resize(rows);
  for (uint32_t g = 0; g < kParamGroupCount; ++g) {
    const size_t width = in.exp_avg[g].size() / in.size();
    auto& values = group_values(out.model, g);
    std::fill(values.begin() + static_cast<std::ptrdiff_t>(in.size() * width), values.end(), 0.0f);
    out.exp_avg[g].resize(rows * width, 0.0f);
    out.exp_avg_sq[g].resize(rows * width, 0.0f);
  }
  out.grad_accum.resize(rows, 0.0f);
  out.denom.resize(rows, 0u);
  out.max_radius.resize(rows, 0.0f);
  return out;
}

TEST_F(McmcTest, RelocationAndGrowthMatchTheReferenceGivenTheDraws) {
  const size_t n = 3000;
  const TrainingState in = random_state(n, 7);
  std::vector<float> plane(n);
  for (size_t i = 0; i < n; ++i) plane[i] = (i % 41 == 3) ? 2.0f : 0.01f * static_cast<float>(i % 7);
  plane[100] = std::numeric_limits<float>::quiet_NaN();  // no plane: never dead by distance
  McmcOptions o;
  o.max_gaussians = 3100;  // growth 0.1 would give 3300: the cap wins
  o.growth = 0.1f;
  o.max_plane_distance_m = 0.5f;
  o.seed = 4;

  TrainableGaussians model(context(), in);
  McmcStrategy mcmc(context());
  DeviceArray<float> d_plane(context(), "plane distances", n);
  d_plane.upload(plane);
  const McmcReport r = mcmc.relocate_and_grow(model, o, 900, &d_plane.buffer());
  const std::vector<uint32_t> dead = mcmc_dead_reference(in.model, o, plane);
  EXPECT_EQ(r.dead(), dead.size());
  EXPECT_EQ(r.dead_nonfinite, 3u);
  EXPECT_GT(r.dead_transparent, 300u);
  EXPECT_GT(r.dead_plane, 50u);
  EXPECT_EQ(r.relocated, dead.size());
  EXPECT_EQ(r.added, 100u);
  EXPECT_EQ(r.after, 3100u);
  ASSERT_EQ(model.size(), 3100u);

  // Targets: the dead rows in index order, then the new rows; sources: live rows.
  const McmcStrategy::Draws draws = mcmc.last_draws();
  ASSERT_EQ(draws.target.size(), dead.size() + 100);
  const std::set<uint32_t> dead_set(dead.begin(), dead.end());
  for (size_t t = 0; t < draws.target.size(); ++t) {
    ASSERT_EQ(draws.target[t], t < dead.size() ? dead[t] : static_cast<uint32_t>(n + t - dead.size())) << t;
    ASSERT_LT(draws.source[t], n) << t;
    ASSERT_EQ(dead_set.count(draws.source[t]), 0u) << "draw " << t << " took dead row " << draws.source[t];
  }

  const TrainingState want = mcmc_relocate_reference(padded(in, 3100), draws.source, draws.target, o);
  const TrainingState got = model.download_state();
  for (uint32_t g = 0; g < kParamGroupCount; ++g) {
    const auto& a = group_values(got.model, g);
    const auto& b = group_values(want.model, g);
    ASSERT_EQ(a.size(), b.size());
    for (size_t j = 0; j < a.size(); ++j) {
      // Relocated opacities and scales: float kernels against the double reference; the rest are copies.
      if (g == kOpacityLogits || g == kLogScales)
        ASSERT_NEAR(a[j], b[j], 2e-5 * std::max(1.0f, std::abs(b[j]))) << kParamGroupNames[g] << " " << j;
      else
        ASSERT_EQ(bits(a[j]), bits(b[j])) << kParamGroupNames[g] << " " << j;
      ASSERT_EQ(bits(got.exp_avg[g][j]), bits(want.exp_avg[g][j]))
          << "exp_avg " << kParamGroupNames[g] << " " << j;
      ASSERT_EQ(bits(got.exp_avg_sq[g][j]), bits(want.exp_avg_sq[g][j])) << "exp_avg_sq " << j;
    }
  }
  for (size_t i = 0; i < got.size(); ++i) {
    ASSERT_EQ(bits(got.grad_accum[i]), bits(want.grad_accum[i])) << i;
    ASSERT_EQ(got.denom[i], want.denom[i]) << i;
    ASSERT_EQ(bits(got.max_radius[i]), bits(want.max_radius[i])) << i;
  }
}

TEST_F(McmcTest, DrawsAreExactlyTheReferencesAndFollowOpacity) {
  // Four live Gaussians (opacities 0.1 .. 0.4) and 20,000 transparent ones to relocate.
  const double opacities[4] = {0.1, 0.2, 0.3, 0.4};
  GaussianModel m = testing::random_scene(20004, 1, 0, 3);
  for (size_t i = 0; i < m.size(); ++i) m.opacity_logits[i] = i < 4 ? logit(opacities[i]) : -9.0f;
  TrainableGaussians model(context(), m);
  McmcStrategy mcmc(context());
  McmcOptions o;
  o.growth = 0;
  o.seed = 11;
  const McmcReport r = mcmc.relocate_and_grow(model, o, 1200);
  EXPECT_EQ(r.relocated, 20000u);
  const McmcStrategy::Draws draws = mcmc.last_draws();
  std::vector<uint32_t> cdf(m.size(), 0);
  uint32_t total = 0;
  for (size_t i = 0; i < m.size(); ++i) {
    cdf[i] = total;
    total += i < 4 ? static_cast<uint32_t>(opacities[i] * MCMC_WEIGHT_LEVELS + 0.5) : 0u;
  }
  double count[4] = {0, 0, 0, 0};
  for (uint32_t t = 0; t < draws.source.size(); ++t) {
    ASSERT_EQ(draws.source[t], mcmc_draw_reference(cdf, total, o.seed, 1200, t)) << t;
    ASSERT_LT(draws.source[t], 4u);
    ++count[draws.source[t]];
  }
  for (int k = 0; k < 4; ++k)  // frequency within 4.5 standard deviations of opacity / sum
    EXPECT_NEAR(count[k] / 20000.0, opacities[k], 4.5 * std::sqrt(0.25 / 20000.0)) << k;
}

TEST_F(McmcTest, CopiesOfOneSourceAreCappedAtFiftyOne) {
  // One live Gaussian drawn 99 times: it and its copies get the n = 51 relocation, finite.
  GaussianModel m = testing::random_scene(100, 1, 0, 5);
  for (size_t i = 0; i < m.size(); ++i) m.opacity_logits[i] = i == 0 ? logit(0.9999) : -9.0f;
  TrainableGaussians model(context(), m);
  McmcStrategy mcmc(context());
  McmcOptions o;
  o.growth = 0;
  mcmc.relocate_and_grow(model, o, 1);
  const GaussianModel got = model.download();
  const double o51 = mcmc_math::relocated_opacity(0.9999, 51u);
  const double delta = std::log(0.9999 / mcmc_normalizer_reference(o51, 51u));
  for (size_t i = 0; i < got.size(); ++i) {
    ASSERT_NEAR(got.opacity_logits[i], std::log(o51 / (1 - o51)), 1e-4) << i;
    ASSERT_NEAR(got.log_scales[3 * i], m.log_scales[0] + delta, 2e-5) << i;
  }
}

TEST_F(McmcTest, NothingAliveLeavesTheModelAsItIs) {
  GaussianModel m = testing::random_scene(50, 1, 0, 9);
  for (auto& l : m.opacity_logits) l = -9.0f;
  TrainableGaussians model(context(), m);
  McmcStrategy mcmc(context());
  const McmcReport r = mcmc.relocate_and_grow(model, McmcOptions{}, 1);
  EXPECT_EQ(r.dead_transparent, 50u);
  EXPECT_EQ(r.relocated, 0u);
  EXPECT_EQ(r.added, 0u);
  EXPECT_EQ(model.size(), 50u);
  const GaussianModel got = model.download();
  for (size_t i = 0; i < got.means.size(); ++i) ASSERT_EQ(bits(got.means[i]), bits(m.means[i]));
}

TEST_F(McmcTest, GrowthStopsAtTheBudgetAndBuffersGrowOnlyAsNeeded) {
  GaussianModel m = testing::random_scene(10, 1, 0, 2);
  for (auto& l : m.opacity_logits) l = 1.0f;
  TrainableGaussians model(context(), m);
  McmcStrategy mcmc(context());
  McmcOptions o;
  o.growth = 1.0f;
  o.max_gaussians = 100;
  const uint32_t expected[] = {20, 40, 80, 100, 100};
  for (uint32_t k = 0; k < 5; ++k) {
    const McmcReport r = mcmc.relocate_and_grow(model, o, k + 1);
    EXPECT_EQ(r.after, expected[k]) << k;
    EXPECT_EQ(model.size(), expected[k]);
    EXPECT_LE(model.capacity(), 100u);  // never beyond the budget
  }
  const GaussianModel got = model.download();
  for (float l : got.opacity_logits) ASSERT_TRUE(std::isfinite(l));
  // The first rows were sources at some point: their parameters moved only by relocation (means are copies).
  for (size_t i = 0; i < got.size(); ++i) {
    bool matches_an_original = false;
    for (size_t j = 0; j < m.size(); ++j)
      matches_an_original |= bits(got.means[3 * i]) == bits(m.means[3 * j]);
    ASSERT_TRUE(matches_an_original) << "row " << i << " is not a copy of an original Gaussian";
  }
}

TEST_F(McmcTest, NoiseMatchesTheReference) {
  GaussianModel m = testing::random_scene(4000, 1, 0, 21);
  std::mt19937 rng(1);
  std::uniform_real_distribution<float> u(-9.0f, 0.0f);
  for (auto& l : m.opacity_logits) l = u(rng);  // many below the gate's 0.005
  TrainableGaussians model(context(), m);
  McmcStrategy mcmc(context());
  McmcOptions o;
  o.seed = 6;
  engine::Sequence s(context());
  mcmc.record_noise(s, model, o, 1.6e-4f, 321);
  s.submit_and_wait();
  const GaussianModel got = model.download();
  const std::vector<double> want = mcmc_noise_reference(m, o, 1.6e-4f, 321);
  size_t moved = 0;
  for (size_t j = 0; j < want.size(); ++j) {
    const double offset = want[j] - m.means[j];
    // float: a few ulps of the mean itself, plus the offset's own float error (Sigma z cancels partly)
    ASSERT_NEAR(got.means[j], want[j], 1e-6 * std::max(1.0, std::abs(want[j])) + 1e-4 * std::abs(offset))
        << j;
    moved += std::abs(offset) > 1e-6;
  }
  EXPECT_GT(moved, want.size() / 4);  // the noise does act
}

TEST_F(McmcTest, RegularizationGradientsMatchTheReference) {
  GaussianModel m = testing::random_scene(1000, 1, 0, 8);
  TrainableGaussians model(context(), m);
  McmcStrategy mcmc(context());
  McmcOptions o;
  DeviceArray<float> g_op(context(), "grad opacity", 1000), g_ls(context(), "grad log-scales", 3000);
  g_op.upload(std::vector<float>(1000, 0.5f));
  g_ls.upload(std::vector<float>(3000, -0.25f));
  Rasterizer::DeviceGrads grads{};
  grads.opacity_logits = &g_op.buffer();
  grads.log_scales = &g_ls.buffer();
  engine::Sequence s(context());
  mcmc.record_regularization(s, model, grads, o);
  s.submit_and_wait();
  std::vector<double> want_op, want_ls;
  mcmc_regularization_reference(m, o, want_op, want_ls);
  const auto got_op = g_op.download(), got_ls = g_ls.download();
  for (size_t i = 0; i < 1000; ++i) ASSERT_NEAR(got_op[i] - 0.5, want_op[i], 1e-7 + 1e-5 * want_op[i]) << i;
  for (size_t j = 0; j < 3000; ++j) ASSERT_NEAR(got_ls[j] + 0.25, want_ls[j], 1e-7 + 1e-5 * want_ls[j]) << j;
}

}  // namespace
}  // namespace litgs::kernels
