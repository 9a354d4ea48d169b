// Adam on the device against torch.optim.Adam's step in double (kernels/optim/adam_reference.h).
#include <gtest/gtest.h>

#include <cmath>
#include <cstring>
#include <limits>
#include <random>
#include <vector>

#include "gpu_test.h"
#include "kernels/optim/adam.h"
#include "kernels/optim/adam_reference.h"
#include "kernels/optim/optim_shared.h"
#include "kernels/optim/trainable_gaussians.h"
#include "splat_scenes.h"

namespace litgs::kernels {
namespace {

using engine::DeviceArray;
using testing::GpuTest;

class AdamTest : public GpuTest {};

uint32_t bits(float x) {
  uint32_t b;
  std::memcpy(&b, &x, 4);
  return b;
}

// 5 steps with fresh random gradients each step; SH-like split of learning rates (period 7, lead 2).
TEST_F(AdamTest, MatchesDoubleReferenceOverFiveSteps) {
  const size_t n = 1037;  // not a multiple of the 256-wide workgroup
  const uint32_t period = 7, lead = 2;
  const float lr = 1e-2f, lr_rest = 5e-4f;
  AdamOptions options;
  std::mt19937 rng(7);
  std::normal_distribution<float> normal(0.0f, 1.0f);
  std::vector<float> params(n);
  for (auto& p : params) p = normal(rng);
  DeviceArray<float> d_params(context(), "params", n), d_grads(context(), "grads", n), d_m(context(), "m", n),
      d_v(context(), "v", n);
  DeviceArray<uint32_t> counters(context(), "counters", ADAM_COUNTER_SLOTS);
  d_params.upload(params);
  d_m.upload(std::vector<float>(n, 0.0f));
  d_v.upload(std::vector<float>(n, 0.0f));
  counters.upload(std::vector<uint32_t>(ADAM_COUNTER_SLOTS, 0u));
  std::vector<double> p_ref(params.begin(), params.end()), m_ref(n, 0.0), v_ref(n, 0.0), g_max(n, 0.0);
  AdamKernel adam(context());
  for (uint32_t step = 1; step <= 5; ++step) {
    std::vector<float> grads(n);
    // Magnitudes from 1e-6 to 1e2: the update must not depend on the gradient's scale.
    for (size_t j = 0; j < n; ++j) grads[j] = normal(rng) * std::pow(10.0f, static_cast<float>(j % 9) - 6.0f);
    d_grads.upload(grads);
    for (size_t j = 0; j < n; ++j) g_max[j] = std::max(g_max[j], double{std::abs(grads[j])});
    engine::Sequence s(context());
    adam.record(s, {&d_params.buffer(), &d_grads.buffer(), &d_m.buffer(), &d_v.buffer(), &counters.buffer()},
                n, options, step, lr, 3, lr_rest, period, lead);
    s.submit_and_wait();
    for (size_t j = 0; j < n; ++j)
      ASSERT_TRUE(adam_reference_step(p_ref[j], m_ref[j], v_ref[j], grads[j],
                                      (j % period) < lead ? lr : lr_rest, options, step));
  }
  const auto p = d_params.download(), m = d_m.download(), v = d_v.download();
  // Tolerance: each step moves a parameter by about lr; float32 rounding of the update (a few ulp of lr)
  // and of the parameter (an ulp of |p|) over 5 steps stays below 1e-6 |p| + 1e-5 lr. The first moment
  // is a signed sum (it may cancel): its error is relative to the largest gradient, 1e-6 |g|max; the second
  // moment is a positive sum: 1e-5 relative.
  for (size_t j = 0; j < n; ++j) {
    const double rate = (j % period) < lead ? lr : lr_rest;
    ASSERT_NEAR(p[j], p_ref[j], 1e-6 * std::max(1.0, std::abs(p_ref[j])) + 1e-5 * rate) << "element " << j;
    ASSERT_NEAR(m[j], m_ref[j], 1e-6 * g_max[j]) << "element " << j;
    ASSERT_NEAR(v[j], v_ref[j], 1e-5 * std::abs(v_ref[j]) + 1e-30) << "element " << j;
    // Every element moved, in the direction that reduces the (first) gradient's sign-weighted loss.
    ASSERT_NE(p[j], params[j]);
  }
  EXPECT_EQ(counters.download()[3], 0u);
}

TEST_F(AdamTest, NonFiniteGradientsLeaveParamsAndMomentsUnchangedAndAreCounted) {
  const size_t n = 300;
  AdamOptions options;
  std::vector<float> params(n), grads(n), m0(n), v0(n);
  for (size_t j = 0; j < n; ++j) {
    params[j] = 0.01f * static_cast<float>(j) - 1.0f;
    grads[j] = std::sin(static_cast<float>(j));
    m0[j] = 0.1f * std::cos(static_cast<float>(j));
    v0[j] = 0.5f + 0.001f * static_cast<float>(j);
  }
  const size_t bad[] = {0, 17, 255, 256, 299};
  grads[0] = std::numeric_limits<float>::quiet_NaN();
  grads[17] = std::numeric_limits<float>::infinity();
  grads[255] = -std::numeric_limits<float>::infinity();
  grads[256] = std::numeric_limits<float>::quiet_NaN();
  grads[299] = 3e38f;  // finite, but its square overflows: v would be infinite
  DeviceArray<float> d_params(context(), "params", n), d_grads(context(), "grads", n), d_m(context(), "m", n),
      d_v(context(), "v", n);
  DeviceArray<uint32_t> counters(context(), "counters", ADAM_COUNTER_SLOTS);
  d_params.upload(params);
  d_grads.upload(grads);
  d_m.upload(m0);
  d_v.upload(v0);
  counters.upload(std::vector<uint32_t>(ADAM_COUNTER_SLOTS, 0u));
  AdamKernel adam(context());
  engine::Sequence s(context());
  adam.record(s, {&d_params.buffer(), &d_grads.buffer(), &d_m.buffer(), &d_v.buffer(), &counters.buffer()}, n,
              options, 4, 1e-3f, 5);
  s.submit_and_wait();
  const auto p = d_params.download(), m = d_m.download(), v = d_v.download();
  const auto c = counters.download();
  EXPECT_EQ(c[5], 5u);
  for (uint32_t k = 0; k < ADAM_COUNTER_SLOTS; ++k)
    if (k != 5) {
      EXPECT_EQ(c[k], 0u);
    }
  for (size_t j = 0; j < n; ++j) {
    const bool is_bad = std::find(std::begin(bad), std::end(bad), j) != std::end(bad);
    ASSERT_TRUE(std::isfinite(p[j]) && std::isfinite(m[j]) && std::isfinite(v[j])) << j;
    if (is_bad) {
      EXPECT_EQ(bits(p[j]), bits(params[j])) << j;
      EXPECT_EQ(bits(m[j]), bits(m0[j])) << j;
      EXPECT_EQ(bits(v[j]), bits(v0[j])) << j;
    } else {
      EXPECT_NE(p[j], params[j]) << j;
    }
  }
}

TEST_F(AdamTest, ZeroElementsRecordsNothing) {
  DeviceArray<float> a(context(), "a", 0);
  DeviceArray<uint32_t> counters(context(), "counters", ADAM_COUNTER_SLOTS);
  AdamKernel adam(context());
  engine::Sequence s(context());
  adam.record(s, {&a.buffer(), &a.buffer(), &a.buffer(), &a.buffer(), &counters.buffer()}, 0, AdamOptions{},
              1, 1e-3f, 0);
  EXPECT_EQ(s.dispatch_count(), 0u);
  EXPECT_THROW(adam.record(s, {&a.buffer(), &a.buffer(), &a.buffer(), &a.buffer(), &counters.buffer()}, 1,
                           AdamOptions{}, 1, 1e-3f, 0),
               std::out_of_range);
}

// The trainable model's step: every group with its own rate (SH degree 0 vs higher at their rates).
TEST_F(AdamTest, TrainableModelStepsEveryGroupAtItsRate) {
  GaussianModel model = testing::random_scene(37, 2, 1, 5);
  TrainableGaussians trainable(context(), model);
  const size_t n = model.size();
  std::mt19937 rng(11);
  std::normal_distribution<float> normal(0.0f, 1.0f);
  GaussianModel grads_host = model;
  for (uint32_t g = 0; g < kParamGroupCount; ++g)
    for (auto& x : group_values(grads_host, g)) x = normal(rng);
  std::vector<std::unique_ptr<DeviceArray<float>>> grads;
  for (uint32_t g = 0; g < kParamGroupCount; ++g) {
    grads.push_back(
        std::make_unique<DeviceArray<float>>(context(), "grad", group_values(grads_host, g).size()));
    grads.back()->upload(group_values(grads_host, g));
  }
  DeviceArray<float> grad2d(context(), "grad2d", 8 * n);
  const Rasterizer::DeviceGrads device_grads{&grads[0]->buffer(), &grads[1]->buffer(), &grads[2]->buffer(),
                                             &grads[3]->buffer(), &grads[4]->buffer(), &grad2d.buffer()};
  const LearningRates lr{1e-3f, 2e-3f, 3e-3f, 4e-3f, 5e-3f, 6e-4f};
  const AdamOptions& o = trainable.adam_options();
  for (uint32_t step = 1; step <= 2; ++step) {
    engine::Sequence s(context());
    trainable.record_adam_step(s, device_grads, lr, step);
    s.submit_and_wait();
  }
  const TrainingState got = trainable.download_state();
  const float rates[kParamGroupCount] = {lr.means, lr.log_scales, lr.quats, lr.opacity_logits, lr.sh_dc};
  const uint32_t sv = model.sh_coeffs() * model.channels;
  for (uint32_t g = 0; g < kParamGroupCount; ++g) {
    const auto& p0 = group_values(model, g);
    const auto& gr = group_values(grads_host, g);
    for (size_t j = 0; j < p0.size(); ++j) {
      double rate = rates[g];
      if (g == kSh && (j % sv) >= model.channels) rate = lr.sh_rest;
      double p = p0[j], m = 0, v = 0;
      for (uint32_t step = 1; step <= 2; ++step) adam_reference_step(p, m, v, gr[j], rate, o, step);
      ASSERT_NEAR(group_values(got.model, g)[j], p, 1e-6 * std::max(1.0, std::abs(p)) + 1e-5 * rate)
          << kParamGroupNames[g] << " " << j;
      ASSERT_NEAR(got.exp_avg[g][j], m, 1e-5 * std::abs(m) + 1e-12);
      ASSERT_NEAR(got.exp_avg_sq[g][j], v, 1e-5 * std::abs(v) + 1e-12);
    }
  }
  for (uint32_t c : trainable.nonfinite_grad_counts()) EXPECT_EQ(c, 0u);
}

}  // namespace
}  // namespace litgs::kernels
