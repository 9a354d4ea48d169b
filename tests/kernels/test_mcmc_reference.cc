// The MCMC strategy's math (kernels/mcmc/mcmc_math.h) in double: the relocation normalizer's quadrature
// against the paper's alternating sum where that sum is still accurate, the properties relocation must
// have, and the hard case that motivated the quadrature.
#include <gtest/gtest.h>

#include <cmath>
#include <vector>

#include "kernels/mcmc/mcmc_math.h"
#include "kernels/mcmc/mcmc_reference.h"

namespace litgs::kernels {
namespace {

TEST(McmcMath, QuadratureMatchesThePapersAlternatingSumForSmallN) {
  for (uint32_t n = 1; n <= 8; ++n)
    for (double x : {0.005, 0.05, 0.3, 0.7, 0.95, 0.999}) {
      const double alt = mcmc_normalizer_alternating(x, n);
      EXPECT_NEAR(mcmc_normalizer_reference(x, n), alt, 1e-10 * std::max(1.0, alt))
          << "n " << n << " x " << x;
      // The kernels' coarser grid (step 0.1 to s = 6), still in double.
      EXPECT_NEAR(mcmc_math::stacked_opacity_integral(x, n, 0.1, 60u), alt, 1e-9 * std::max(1.0, alt))
          << "n " << n << " x " << x;
    }
}

TEST(McmcMath, OneCopyKeepsTheGaussian) {
  for (double o : {0.006, 0.2, 0.5, 0.99}) {
    EXPECT_NEAR(mcmc_math::relocated_opacity(o, 1u), o, 1e-15);
    EXPECT_NEAR(mcmc_math::relocation_log_scale_delta(o, o, 1u), 0.0, 1e-10);
  }
}

TEST(McmcMath, StackedCopiesKeepTheOriginalsPeakOpacity) {
  for (uint32_t n : {2u, 5u, 51u})
    for (double o : {0.006, 0.3, 0.999}) {
      const double o_new = mcmc_math::relocated_opacity(o, n);
      EXPECT_NEAR(1.0 - std::pow(1.0 - o_new, n), o, 1e-12) << n << " " << o;
      EXPECT_LT(o_new, o);
    }
}

// The paper's sum at n = 51 for the most opaque Gaussian float allows (1 - 2^-23): the copies' opacity is
// 0.28, and the alternating terms grow to ~1e5 before cancelling to a result of about 2, so a float
// evaluation (as a float kernel of the sum would do) loses three of its seven digits. The positive integral
// has no cancellation: it lies between its bounds, grows with n, and the kernels' grid agrees with the fine
// one.
TEST(McmcMathHardCase, FiftyOneCopiesOfANearlyOpaqueGaussian) {
  const double o = 1.0 - 1.0 / 8388608.0;
  double previous = 0;
  for (uint32_t n = 1; n <= MCMC_MAX_COPIES; ++n) {
    const double x = mcmc_math::relocated_opacity(o, n);
    const double fine = mcmc_normalizer_reference(x, n);
    const double coarse = mcmc_math::stacked_opacity_integral(x, n, 0.1, 60u);
    ASSERT_TRUE(std::isfinite(fine));
    EXPECT_NEAR(coarse, fine, 1e-9 * fine) << n;
    // n copies of opacity x sum to at most n x (no overlap loss) and at least the original's o.
    EXPECT_LE(fine, n * x + 1e-12) << n;
    EXPECT_GE(fine, o - 1e-12) << n;
    EXPECT_GT(fine, previous) << n;  // more copies spread the same peak wider
    previous = fine;
  }
  // Float evaluation of the alternating form, as a float kernel would do it, is far off.
  const double x51 = mcmc_math::relocated_opacity(o, 51u);
  float alt_f = 0;
  for (uint32_t i = 1; i <= 51; ++i) {
    float binom = 1;
    for (uint32_t k = 0; k < i; ++k) {
      const float term = binom * std::pow(static_cast<float>(x51), static_cast<float>(k + 1)) /
                         std::sqrt(static_cast<float>(k + 1));
      alt_f += (k % 2 == 0) ? term : -term;
      binom = binom * static_cast<float>(i - 1 - k) / static_cast<float>(k + 1);
    }
  }
  const double truth = mcmc_normalizer_reference(x51, 51u);
  EXPECT_GT(std::abs(alt_f - truth) / truth, 1e-5) << "float alternating sum " << alt_f << " vs " << truth;
}

TEST(McmcMath, NoiseGateMovesOnlyNearlyTransparentGaussians) {
  const auto logit = [](double o) { return std::log(o / (1 - o)); };
  EXPECT_NEAR(mcmc_math::noise_gate(logit(0.001)), 1.0 / (1.0 + std::exp(-0.4)), 1e-9);
  EXPECT_NEAR(mcmc_math::noise_gate(logit(0.005)), 0.5, 1e-9);
  EXPECT_LT(mcmc_math::noise_gate(logit(0.05)), 0.02);
  EXPECT_LT(mcmc_math::noise_gate(logit(0.5)), 1e-20);
}

TEST(McmcMath, NoiseNormalsHaveUnitMomentsAndDependOnlyOnTheirCounter) {
  double sum = 0, sq = 0;
  const uint32_t n = 20000;
  for (uint32_t i = 0; i < n; ++i) {
    const auto z = mcmc_math::noise_normals(3u, 17u, i);
    for (int k = 0; k < 3; ++k) {
      sum += z[k];
      sq += z[k] * z[k];
    }
  }
  EXPECT_NEAR(sum / (3 * n), 0.0, 0.02);
  EXPECT_NEAR(sq / (3 * n), 1.0, 0.03);
  EXPECT_EQ(mcmc_math::noise_normals(3u, 17u, 5u).x, mcmc_math::noise_normals(3u, 17u, 5u).x);
  EXPECT_NE(mcmc_math::noise_normals(3u, 17u, 5u).x, mcmc_math::noise_normals(3u, 18u, 5u).x);
}

TEST(McmcOptions, BadFieldsAreNamed) {
  McmcOptions o;
  o.max_gaussians = 0;
  EXPECT_THROW(
      try { o.check(); } catch (const std::invalid_argument& e) {
        EXPECT_NE(std::string(e.what()).find("max_gaussians"), std::string::npos);
        throw;
      },
      std::invalid_argument);
  o = {};
  o.growth = -1;
  EXPECT_THROW(o.check(), std::invalid_argument);
  o = {};
  o.max_plane_distance_m = std::nanf("");
  EXPECT_THROW(o.check(), std::invalid_argument);
}

}  // namespace
}  // namespace litgs::kernels
