// The losses' CPU references: SSIM against a direct windowed evaluation, both gradients against central
// finite differences, and the window literals shared with the kernels against their formula.
#include <gtest/gtest.h>

#include <cmath>
#include <random>
#include <vector>

#include "kernels/loss/loss_reference.h"
#include "kernels/loss/loss_shared.h"

namespace litgs::kernels {
namespace {

std::vector<double> random_image(size_t n, uint32_t seed, double lo = 0.0, double hi = 1.0) {
  std::mt19937 rng(seed);
  std::uniform_real_distribution<double> u(lo, hi);
  std::vector<double> v(n);
  for (auto& x : v) x = u(rng);
  return v;
}

TEST(LossReference, WindowLiteralsMatchTheFormula) {
  const std::vector<double> w = ssim_window();
  const double literals[] = {SSIM_W0, SSIM_W1, SSIM_W2, SSIM_W3, SSIM_W4, SSIM_W5};
  double sum = 0.0;
  for (int k = 0; k <= SSIM_RADIUS; ++k) {
    EXPECT_NEAR(literals[k], w[SSIM_RADIUS + k], 1e-8 * w[SSIM_RADIUS + k])
        << "k = " << k << " (literals must be float-exact)";
    EXPECT_DOUBLE_EQ(w[SSIM_RADIUS + k], w[SSIM_RADIUS - k]);
  }
  for (double v : w) sum += v;
  EXPECT_NEAR(sum, 1.0, 1e-15);
}

// SSIM with the 2D window evaluated directly at every pixel (zero padding), independent of the separable
// blur of the reference.
double direct_mean_ssim(const std::vector<double>& x, const std::vector<double>& y, uint32_t c, uint32_t w,
                        uint32_t h) {
  const std::vector<double> g = ssim_window();
  double total = 0.0;
  for (uint32_t ch = 0; ch < c; ++ch)
    for (int py = 0; py < static_cast<int>(h); ++py)
      for (int px = 0; px < static_cast<int>(w); ++px) {
        double mx = 0, my = 0, exx = 0, eyy = 0, exy = 0;
        for (int dy = -5; dy <= 5; ++dy)
          for (int dx = -5; dx <= 5; ++dx) {
            const int qx = px + dx, qy = py + dy;
            if (qx < 0 || qy < 0 || qx >= static_cast<int>(w) || qy >= static_cast<int>(h)) continue;
            const double wt = g[dy + 5] * g[dx + 5];
            const size_t i = (size_t{ch} * h + qy) * w + qx;
            mx += wt * x[i];
            my += wt * y[i];
            exx += wt * x[i] * x[i];
            eyy += wt * y[i] * y[i];
            exy += wt * x[i] * y[i];
          }
        const double c1 = 0.01 * 0.01, c2 = 0.03 * 0.03;
        total += (2 * mx * my + c1) * (2 * (exy - mx * my) + c2) /
                 ((mx * mx + my * my + c1) * (exx - mx * mx + eyy - my * my + c2));
      }
  return total / (double(c) * w * h);
}

TEST(LossReference, SsimMatchesDirectWindowedEvaluation) {
  for (uint32_t c : {1u, 3u}) {
    const uint32_t w = 13, h = 11;
    const auto x = random_image(size_t{c} * w * h, 1), y = random_image(size_t{c} * w * h, 2);
    const auto r = photometric_loss_reference(x, y, c, w, h, 0.2, false);
    EXPECT_NEAR(r.mean_ssim, direct_mean_ssim(x, y, c, w, h), 1e-13);
    double l1 = 0.0;
    for (size_t i = 0; i < x.size(); ++i) l1 += std::abs(x[i] - y[i]);
    EXPECT_NEAR(r.mean_l1, l1 / static_cast<double>(x.size()), 1e-15);
    EXPECT_NEAR(r.loss, 0.8 * r.mean_l1 + 0.2 * (1.0 - r.mean_ssim), 1e-15);
    EXPECT_TRUE(r.grad.empty());
  }
}

TEST(LossReference, IdenticalImagesGiveSsimOneAndZeroGradient) {
  const auto x = random_image(3 * 13 * 11, 5);
  const auto r = photometric_loss_reference(x, x, 3, 13, 11);
  EXPECT_NEAR(r.mean_ssim, 1.0, 1e-15);
  EXPECT_NEAR(r.loss, 0.0, 1e-15);
  for (double g : r.grad) EXPECT_NEAR(g, 0.0, 1e-15);
}

// Central differences of the loss w.r.t. every pixel, compared with the analytic gradient: worst error
// relative to the largest gradient component.
void check_photometric_gradient(uint32_t c, uint32_t w, uint32_t h, double lambda, uint32_t seed) {
  const auto x0 = random_image(size_t{c} * w * h, seed), y = random_image(size_t{c} * w * h, seed + 100);
  const auto r = photometric_loss_reference(x0, y, c, w, h, lambda, true);
  ASSERT_EQ(r.grad.size(), x0.size());
  const double step = 1e-6;
  double worst = 0.0, scale = 0.0;
  std::vector<double> x = x0;
  for (size_t i = 0; i < x.size(); ++i) {
    ASSERT_GT(std::abs(x0[i] - y[i]), 2 * step) << "the L1 kink would sit inside the stencil";
    x[i] = x0[i] + step;
    const double lp = photometric_loss_reference(x, y, c, w, h, lambda, false).loss;
    x[i] = x0[i] - step;
    const double lm = photometric_loss_reference(x, y, c, w, h, lambda, false).loss;
    x[i] = x0[i];
    const double fd = (lp - lm) / (2 * step);
    worst = std::max(worst, std::abs(fd - r.grad[i]));
    scale = std::max(scale, std::abs(r.grad[i]));
  }
  ASSERT_GT(scale, 0.0);
  EXPECT_LT(worst / scale, 1e-6) << "C " << c << ", lambda " << lambda << ": worst |fd - analytic| " << worst
                                 << " against max |grad| " << scale;
}

TEST(LossReference, PhotometricGradientMatchesFiniteDifferencesOneChannel) {
  check_photometric_gradient(1, 13, 11, 0.2, 7);
}
TEST(LossReference, PhotometricGradientMatchesFiniteDifferencesThreeChannels) {
  check_photometric_gradient(3, 13, 11, 0.2, 8);
}
TEST(LossReference, SsimOnlyGradientMatchesFiniteDifferences) {
  check_photometric_gradient(1, 13, 11, 1.0, 9);
}
TEST(LossReference, SmallerThanTheWindowGradientMatchesFiniteDifferences) {
  check_photometric_gradient(3, 4, 3, 0.2, 10);
}

struct GeoScene {
  uint32_t w = 13, h = 11;
  double fx = 12.0, fy = 11.0, cx = 6.3, cy = 5.4;
  std::vector<double> depth;
  std::vector<float> points, normals;
  uint32_t valid = 0;
};

GeoScene random_geo_scene(uint32_t seed) {
  GeoScene s;
  std::mt19937 rng(seed);
  std::uniform_real_distribution<double> u(-1.0, 1.0);
  const size_t n = size_t{s.w} * s.h;
  s.depth.resize(n);
  s.points.assign(4 * n, 0.0f);
  s.normals.assign(4 * n, 0.0f);
  for (size_t i = 0; i < n; ++i) {
    s.depth[i] = 3.0 + u(rng);
    if (i % 7 == 3) s.depth[i] = 0.0;  // nothing rendered
    if (i % 5 == 1) continue;          // no LiDAR point
    const double nx = u(rng), ny = u(rng), nz = 1.5 + u(rng), len = std::sqrt(nx * nx + ny * ny + nz * nz);
    s.normals[4 * i + 0] = static_cast<float>(nx / len);
    s.normals[4 * i + 1] = static_cast<float>(ny / len);
    s.normals[4 * i + 2] = static_cast<float>(nz / len);
    s.points[4 * i + 0] = static_cast<float>(u(rng));
    s.points[4 * i + 1] = static_cast<float>(u(rng));
    s.points[4 * i + 2] = static_cast<float>(3.0 + u(rng));
    s.points[4 * i + 3] = 1.0f;
    ++s.valid;
  }
  return s;
}

void expect_geometric_gradient_matches_fd(double robust_scale) {
  SCOPED_TRACE("robust scale " + std::to_string(robust_scale));
  GeoScene s = random_geo_scene(3);
  const auto r = geometric_loss_reference(s.depth, s.points, s.normals, s.w, s.h, s.fx, s.fy, s.cx, s.cy,
                                          s.valid, robust_scale);
  const double step = 1e-6;
  double worst = 0.0, scale = 0.0;
  uint32_t counted = 0;
  for (size_t i = 0; i < s.depth.size(); ++i) {
    if (s.depth[i] == 0.0) {  // skipped pixels: no gradient (a step would cross the D > 0 boundary)
      EXPECT_EQ(r.grad_depth[i], 0.0);
      continue;
    }
    const double d0 = s.depth[i];
    s.depth[i] = d0 + step;
    const double lp = geometric_loss_reference(s.depth, s.points, s.normals, s.w, s.h, s.fx, s.fy, s.cx, s.cy,
                                               s.valid, robust_scale)
                          .loss;
    s.depth[i] = d0 - step;
    const double lm = geometric_loss_reference(s.depth, s.points, s.normals, s.w, s.h, s.fx, s.fy, s.cx, s.cy,
                                               s.valid, robust_scale)
                          .loss;
    s.depth[i] = d0;
    const double fd = (lp - lm) / (2 * step);
    worst = std::max(worst, std::abs(fd - r.grad_depth[i]));
    scale = std::max(scale, std::abs(r.grad_depth[i]));
    if (s.points[4 * i + 3] == 0.0f)
      EXPECT_EQ(r.grad_depth[i], 0.0);
    else
      ++counted;
  }
  EXPECT_EQ(r.counted, counted);
  ASSERT_GT(scale, 0.0);
  EXPECT_LT(worst / scale, 1e-7) << "worst |fd - analytic| " << worst << " against max |grad| " << scale;
}

TEST(LossReference, GeometricGradientMatchesFiniteDifferences) {
  expect_geometric_gradient_matches_fd(0.0);
}

TEST(LossReference, CauchyGeometricGradientMatchesFiniteDifferences) {
  for (const double scale : {0.02, 0.1, 1.0}) expect_geometric_gradient_matches_fd(scale);
}

TEST(LossReference, CauchyKernelIsTheSquareForSmallResidualsAndBoundsTheOutliersPull) {
  // One pixel, plane z = 2, n = +z, seen at depth 2 + e: residual -e, scale 0.05 m.
  auto one = [](double e, double scale) {
    std::vector<double> depth = {2.0 + e};
    std::vector<float> points = {0.0f, 0.0f, 2.0f, 1.0f}, normals = {0, 0, 1, 0};
    return geometric_loss_reference(depth, points, normals, 1, 1, 10, 10, 0.5, 0.5, 1, scale);
  };
  // At 0.1 mm (x = r^2 / s^2 = 4e-6) both agree to x / 2 and x.
  EXPECT_NEAR(one(1e-4, 0.05).loss, one(1e-4, 0.0).loss, 3e-6 * one(1e-4, 0.0).loss);
  EXPECT_NEAR(one(1e-4, 0.05).grad_depth[0], one(1e-4, 0.0).grad_depth[0], 5e-6 * 2e-4);
  // At 0.5 m (ten scales off) the squared loss pulls 101x harder than the kernel.
  EXPECT_NEAR(one(0.5, 0.0).grad_depth[0] / one(0.5, 0.05).grad_depth[0], 101.0, 1e-9);
  EXPECT_NEAR(one(0.5, 0.05).loss, 0.0025 * std::log(101.0), 1e-15);
}

TEST(LossReference, GeometricValueByHand) {
  // One pixel of a 2x1 view, a fronto-parallel plane z = 2 seen at depth 2.5: residual -0.5 (n = +z).
  std::vector<double> depth = {2.5, 1.0};
  std::vector<float> points = {0.3f, -0.1f, 2.0f, 1.0f, 0, 0, 0, 0};
  std::vector<float> normals = {0, 0, 1, 0, 0, 0, 0, 0};
  const auto r = geometric_loss_reference(depth, points, normals, 2, 1, 10, 10, 1, 0.5, 1);
  EXPECT_NEAR(r.loss, 0.25, 1e-15);
  EXPECT_NEAR(r.grad_depth[0], 1.0, 1e-15);  // -2 r (n . ray) = -2 (-0.5) (1)
  EXPECT_EQ(r.grad_depth[1], 0.0);
  EXPECT_EQ(r.counted, 1u);
  const auto none = geometric_loss_reference(depth, points, normals, 2, 1, 10, 10, 1, 0.5, 0);
  EXPECT_EQ(none.loss, 0.0);
  EXPECT_EQ(none.grad_depth[0], 0.0);
}

TEST(LossReference, PsnrAndSsimHelpers) {
  const std::vector<float> a = {0.0f, 0.5f, 1.0f, 0.25f};
  std::vector<float> b = a;
  EXPECT_TRUE(std::isinf(psnr(a, b)));
  EXPECT_NEAR(ssim_reference(a, b, 1, 2, 2), 1.0, 1e-15);
  b[0] = 0.1f;  // MSE = 0.01 / 4
  EXPECT_NEAR(psnr(a, b), 10.0 * std::log10(400.0), 1e-5);
  EXPECT_LT(ssim_reference(a, b, 1, 2, 2), 1.0);
  EXPECT_THROW(psnr(a, std::vector<float>(3)), std::invalid_argument);
}

}  // namespace
}  // namespace litgs::kernels
