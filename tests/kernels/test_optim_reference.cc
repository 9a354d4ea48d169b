// CPU tests of the optimizer's options and references: the 3DGS learning-rate schedule, Adam's first step,
// the densification parameters and the split sampler.
#include <gtest/gtest.h>

#include <cmath>
#include <limits>
#include <stdexcept>

#include "kernels/densify/densify.h"
#include "kernels/densify/densify_math.h"
#include "kernels/densify/densify_reference.h"
#include "kernels/optim/adam.h"
#include "kernels/optim/adam_reference.h"

namespace litgs::kernels {
namespace {

TEST(AdamOptionsTest, MeansRateFollowsThe3dgsExponentialSchedule) {
  AdamOptions o;
  const float extent = 4.0f;
  EXPECT_NEAR(o.means_lr(0, 30000, extent), 1.6e-4 * 4, 1e-10);
  EXPECT_NEAR(o.means_lr(30000, 30000, extent), 1.6e-6 * 4, 1e-12);
  EXPECT_NEAR(o.means_lr(15000, 30000, extent), 1.6e-5 * 4, 1e-11);  // log-linear: the geometric mean
  EXPECT_NEAR(o.means_lr(90000, 30000, extent), 1.6e-6 * 4, 1e-12);  // clamped after the run
  EXPECT_GT(o.means_lr(100, 30000, extent), o.means_lr(101, 30000, extent));
  // The delay (3DGS lr_delay_steps, off by default): starts at delay_mult x the rate, full after the delay.
  o.means_lr_delay_steps = 1000;
  EXPECT_NEAR(o.means_lr(0, 30000, extent), 0.01 * 1.6e-4 * 4, 1e-12);
  AdamOptions plain;
  EXPECT_NEAR(o.means_lr(1000, 30000, extent), plain.means_lr(1000, 30000, extent), 1e-12);
  const LearningRates r = plain.rates(0, 30000, extent);
  EXPECT_FLOAT_EQ(r.sh_dc, 2.5e-3f);
  EXPECT_FLOAT_EQ(r.sh_rest, 2.5e-3f / 20);
  EXPECT_FLOAT_EQ(r.opacity_logits, 0.025f);
  EXPECT_FLOAT_EQ(r.log_scales, 5e-3f);
  EXPECT_FLOAT_EQ(r.quats, 1e-3f);
}

TEST(AdamOptionsTest, CheckNamesTheBadField) {
  AdamOptions o;
  o.beta2 = 1.0f;
  try {
    o.check();
    FAIL() << "no exception";
  } catch (const std::invalid_argument& e) {
    EXPECT_NE(std::string(e.what()).find("beta2"), std::string::npos) << e.what();
  }
  DensifyOptions d;
  d.split_scale_divisor = 1.0f;
  EXPECT_THROW(d.check(), std::invalid_argument);
}

TEST(AdamReferenceTest, FirstStepMovesByTheRateAgainstTheGradient) {
  AdamOptions o;
  for (double g : {1e-8, -3.0, 250.0}) {
    double p = 1.0, m = 0.0, v = 0.0;
    ASSERT_TRUE(adam_reference_step(p, m, v, g, 0.01, o, 1));
    // m_hat = g, v_hat = g^2: the update is lr g / (|g| + eps).
    EXPECT_NEAR(p, 1.0 - 0.01 * (g > 0 ? 1 : -1), 1e-9) << g;
  }
  double p = 1.0, m = 0.5, v = 0.25;
  EXPECT_FALSE(adam_reference_step(p, m, v, std::numeric_limits<double>::quiet_NaN(), 0.01, o, 3));
  EXPECT_EQ(p, 1.0);
  EXPECT_EQ(m, 0.5);
  EXPECT_EQ(v, 0.25);
}

TEST(DensifyParamsTest, ThresholdsInLogSpaceAndTheBudget) {
  DensifyOptions o;
  o.max_gaussians = 1000;
  DensifyParams p = make_densify_params(o, 2.0f, 100, 900, 16, true);
  EXPECT_FLOAT_EQ(p.log_clone_max_scale, static_cast<float>(std::log(0.02)));
  EXPECT_FLOAT_EQ(p.log_world_max_scale, static_cast<float>(std::log(0.2)));
  EXPECT_FLOAT_EQ(p.min_opacity_logit, static_cast<float>(std::log(0.005 / 0.995)));
  EXPECT_EQ(p.budget, 100u);
  EXPECT_EQ(p.flags & DENSIFY_FLAG_SIZE_PRUNE, 0u);   // before the first opacity reset
  EXPECT_EQ(p.flags & DENSIFY_FLAG_PLANE_PRUNE, 0u);  // infinite bound: off
  o.max_plane_distance_m = 0.2f;
  p = make_densify_params(o, 2.0f, 3001, 1200, 16, true);
  EXPECT_EQ(p.budget, 0u);
  EXPECT_NE(p.flags & DENSIFY_FLAG_SIZE_PRUNE, 0u);
  EXPECT_NE(p.flags & DENSIFY_FLAG_PLANE_PRUNE, 0u);
  EXPECT_THROW(make_densify_params(o, 0.0f, 1, 1, 1, false), std::invalid_argument);
}

TEST(DensifyReferenceTest, SplitSamplesAreTruncatedStandardNormals) {
  double sum = 0, sum2 = 0, max_abs = 0;
  const int n = 20000;
  for (int i = 0; i < n; ++i) {
    double z[3];
    split_normals_reference(1, 2, static_cast<uint32_t>(i), static_cast<uint32_t>(i % 2), z);
    for (double x : z) {
      sum += x;
      sum2 += x * x;
      max_abs = std::max(max_abs, std::abs(x));
    }
  }
  const double mean = sum / (3 * n), var = sum2 / (3 * n) - mean * mean;
  EXPECT_NEAR(mean, 0.0, 0.02);
  EXPECT_NEAR(var, 0.973, 0.03);  // a standard normal truncated at 3 has variance 0.973
  EXPECT_LE(max_abs, 3.0);
  // Seed, step, index and child each change the sample.
  double a[3], b[3];
  split_normals_reference(1, 2, 3, 0, a);
  for (int k = 0; k < 4; ++k) {
    split_normals_reference(1 + (k == 0), 2 + (k == 1), 3 + (k == 2), k == 3 ? 1 : 0, b);
    EXPECT_NE(a[0], b[0]) << k;
  }
}

TEST(DensifyReferenceTest, RowCountIdentityAndPruneOrder) {
  GaussianModel m;
  m.channels = 1;
  m.sh_degree = 0;
  m.resize(4);
  for (size_t i = 0; i < 4; ++i) {
    m.quats[4 * i] = 1.0f;
    for (int a = 0; a < 3; ++a) m.log_scales[3 * i + a] = std::log(0.005f);
  }
  m.opacity_logits = {0.0f, -10.0f, std::numeric_limits<float>::quiet_NaN(), 0.0f};  // NaN: non-finite first
  TrainingState s = TrainingState::fresh(m);
  s.denom = {1, 1, 1, 1};
  s.grad_accum = {1.0f, 1.0f, 1.0f, 0.0f};
  DensifyReport r;
  const TrainingState out =
      densify_reference(s, make_densify_params(DensifyOptions{}, 1.0f, 10, 4, 1, false), true, {}, &r);
  EXPECT_EQ(r.cloned, 1u);  // only the opaque candidate; pruned rows never densify
  EXPECT_EQ(r.pruned_opacity, 1u);
  EXPECT_EQ(r.pruned_nonfinite, 1u);
  EXPECT_EQ(r.after, 3u);
  EXPECT_EQ(out.size(), 3u);
  EXPECT_EQ(r.after, r.before + r.cloned + r.split - r.pruned());
}

}  // namespace
}  // namespace litgs::kernels
