// Closed-form oracles for the rasterizer, derived by hand and written without kernels/splat/splat_math.h: the
// device kernels and the CPU reference (reference.cc) share that header, so a convention error in it (pixel
// centres, the projection's Jacobian, the low-pass, the alpha falloff, the compositing order, the expected
// depth) would pass every parity test between them. Both are checked here against the same expectations.
//
// The conventions, as documented (kernels/splat/splat_types.h, splat_shared.h) and derived below:
// - pixel (i, j) has its centre at (i + 0.5, j + 0.5); a camera point (x, y, z) projects to
//   (fx x / z + cx, fy y / z + cy);
// - a Gaussian of world covariance s^2 I at camera point p = (x, y, z) has the 2D covariance
//   J (s^2 I) J^T + 0.3 I, J = [[fx/z, 0, -fx x/z^2], [0, fy/z, -fy y/z^2]] (EWA, with the 0.3 px^2
//   low-pass); on the optical axis that is ((f s / z)^2 + 0.3) I;
// - its alpha at a pixel at offset d from the projected mean is min(0.99, o exp(-d^T Sigma^-1 d / 2)),
//   skipped below 1/255; Gaussians are composited front to back by depth, C = sum T_k a_k c_k with
//   T_k = prod_{j<k} (1 - a_j), alpha = 1 - T, and a pixel stops before a Gaussian that would take T below
//   1e-4; the expected depth is sum(T_k a_k z_k) / sum(T_k a_k) (0 where that sum is below 1e-6);
// - colour from degree-0 SH: Y_0^0 c + 0.5 with Y_0^0 = 1 / (2 sqrt(pi)).
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <numbers>
#include <string>
#include <vector>

#include "gpu_test.h"
#include "kernels/splat/rasterizer.h"
#include "kernels/splat/reference.h"

namespace litgs {
namespace {

using kernels::GaussianModel;
using kernels::SplatCamera;

constexpr uint32_t kSize = 64;  // a 64x64 image: 4x4 tiles
constexpr double kF = 100.0;    // focal length, pixels
constexpr double kC = 32.5;     // principal point: the centre of pixel (32, 32)

// One isotropic Gaussian as the test states it; the rasterizers see its float32-rounded parameters, and the
// expectations below use those same rounded values.
struct Iso {
  double x, y, z;  // camera (= world) point, metres
  double s;        // scale, metres
  double opacity;  // o, before the 0.99 clamp
  double colour;   // 0..1
};

SplatCamera camera() {
  SplatCamera c;  // at the origin, looking down +z
  c.fx = c.fy = kF;
  c.cx = c.cy = kC;
  c.width = c.height = kSize;
  c.sh_degree = 0;
  return c;
}

GaussianModel model(const std::vector<Iso>& gs) {
  GaussianModel m;
  m.channels = 1;
  m.sh_degree = 0;
  m.resize(gs.size());
  const double y00 = 0.5 / std::sqrt(std::numbers::pi);
  for (size_t i = 0; i < gs.size(); ++i) {
    const Iso& g = gs[i];
    m.means[3 * i] = static_cast<float>(g.x);
    m.means[3 * i + 1] = static_cast<float>(g.y);
    m.means[3 * i + 2] = static_cast<float>(g.z);
    for (int a = 0; a < 3; ++a) m.log_scales[3 * i + a] = static_cast<float>(std::log(g.s));
    m.quats[4 * i] = 1.0f;  // w x y z: no rotation
    m.opacity_logits[i] = static_cast<float>(std::log(g.opacity / (1.0 - g.opacity)));
    m.sh[i] = static_cast<float>((g.colour - 0.5) / y00);
  }
  return m;
}

// The parameters as the rasterizers see them (float32), back in double.
Iso as_stored(const GaussianModel& m, size_t i) {
  const double y00 = 0.5 / std::sqrt(std::numbers::pi);
  Iso g;
  g.x = m.means[3 * i];
  g.y = m.means[3 * i + 1];
  g.z = m.means[3 * i + 2];
  g.s = std::exp(static_cast<double>(m.log_scales[3 * i]));
  g.opacity = 1.0 / (1.0 + std::exp(-static_cast<double>(m.opacity_logits[i])));
  g.colour = y00 * m.sh[i] + 0.5;
  return g;
}

// Unclamped alpha of `g` at the centre of pixel (i, j), by the hand-derived covariance above.
double raw_alpha(const Iso& g, uint32_t i, uint32_t j) {
  const double u = kF * g.x / g.z + kC, v = kF * g.y / g.z + kC;
  const double k = kF / g.z, tx = g.x / g.z, ty = g.y / g.z;  // J = k [[1, 0, -tx], [0, 1, -ty]]
  const double s2 = g.s * g.s;
  const double a = s2 * k * k * (1 + tx * tx) + 0.3, b = s2 * k * k * tx * ty,
               c = s2 * k * k * (1 + ty * ty) + 0.3;
  const double det = a * c - b * b;
  const double du = i + 0.5 - u, dv = j + 0.5 - v;
  const double q = (c * du * du - 2 * b * du * dv + a * dv * dv) / det;  // d^T Sigma^-1 d
  return g.opacity * std::exp(-0.5 * q);
}

struct Pixel {
  double colour = 0, alpha = 0, depth = 0;
  bool borderline = false;  // a threshold decision within rounding of the float32 kernels: not compared
};

// Front-to-back compositing of `gs` at pixel (i, j), as stated at the top of the file.
Pixel composite(std::vector<Iso> gs, uint32_t i, uint32_t j) {
  std::stable_sort(gs.begin(), gs.end(), [](const Iso& a, const Iso& b) { return a.z < b.z; });
  Pixel p;
  double T = 1, wz = 0;
  for (const Iso& g : gs) {
    const double raw = raw_alpha(g, i, j);
    const double a = std::min(0.99, raw);
    if (std::abs(raw - 1.0 / 255) < 1e-4 / 255) p.borderline = true;
    if (a < 1.0 / 255) continue;
    if (std::abs(T * (1 - a) - 1e-4) < 1e-8) p.borderline = true;
    if (T * (1 - a) < 1e-4) break;
    p.colour += T * a * g.colour;
    wz += T * a * g.z;
    T *= 1 - a;
  }
  p.alpha = 1 - T;
  p.depth = p.alpha >= 1e-6 ? wz / p.alpha : 0;
  return p;
}

struct Rendered {
  std::string who;
  double tolerance;
  std::vector<double> image, alpha, depth;  // [H][W] (one channel)
};

class RasterizerClosedForm : public testing::GpuTest {
 protected:
  // The device rasterizer (float32) and the CPU reference (double) of the same model.
  std::vector<Rendered> render(const GaussianModel& m) {
    kernels::DeviceGaussians g(context(), m);
    kernels::Rasterizer r(context(), 1);
    r.forward(g, camera());
    const auto gpu = r.download_images();
    const auto ref = kernels::reference_forward(m, camera());
    const auto d = [](const auto& v) { return std::vector<double>(v.begin(), v.end()); };
    return {{"device", 2e-6, d(gpu.image), d(gpu.alpha), d(gpu.depth)},
            {"reference", 1e-9, d(ref.image), d(ref.alpha), d(ref.depth)}};
  }

  // Every pixel of both renders against composite(); returns how many pixels were compared.
  size_t expect_matches_everywhere(const std::vector<Iso>& stated) {
    const GaussianModel m = model(stated);
    std::vector<Iso> gs;
    for (size_t i = 0; i < m.size(); ++i) gs.push_back(as_stored(m, i));
    size_t compared = 0;
    for (const Rendered& r : render(m)) {
      SCOPED_TRACE(r.who);
      size_t bad = 0;
      for (uint32_t j = 0; j < kSize; ++j)
        for (uint32_t i = 0; i < kSize; ++i) {
          const Pixel want = composite(gs, i, j);
          if (want.borderline) continue;
          ++compared;
          const size_t px = size_t{j} * kSize + i;
          const double depth_tol = r.tolerance * 10 * (1 + want.depth);  // depth = a ratio of sums
          if (std::abs(r.alpha[px] - want.alpha) > r.tolerance ||
              std::abs(r.image[px] - want.colour) > r.tolerance ||
              std::abs(r.depth[px] - want.depth) > depth_tol) {
            if (++bad <= 5)
              ADD_FAILURE() << "pixel (" << i << ", " << j << "): alpha " << r.alpha[px] << " want "
                            << want.alpha << ", colour " << r.image[px] << " want " << want.colour
                            << ", depth " << r.depth[px] << " want " << want.depth;
          }
        }
      EXPECT_EQ(bad, 0u);
    }
    return compared;
  }
};

TEST_F(RasterizerClosedForm, IsotropicGaussianOnTheOpticalAxis) {
  // sigma^2 = (f s / z)^2 + 0.3 = (100 * 0.2 / 4)^2 + 0.3 = 25.3 px^2, centred on pixel (32, 32).
  const Iso stated{0, 0, 4, 0.2, 0.8, 0.7};
  const GaussianModel m = model({stated});
  const Iso g = as_stored(m, 0);
  const double sigma2 = std::pow(kF * g.s / g.z, 2) + 0.3;
  ASSERT_NEAR(sigma2, 25.3, 1e-5);
  // alpha = o exp(-d^2 / (2 sigma^2)) falls below 1/255 beyond d_max = sqrt(2 sigma^2 ln(255 o)).
  const double d_max = std::sqrt(2 * sigma2 * std::log(255 * g.opacity));
  const auto last = static_cast<uint32_t>(std::floor(d_max));  // whole pixels right of the centre pixel
  ASSERT_EQ(last, 16u);
  ASSERT_GT(d_max - last, 0.05) << "not a borderline pixel";
  // Over the image (the footprint lies well inside it): the integral of o exp(-r^2 / (2 sigma^2)) over the
  // plane, 2 pi sigma^2 o, less the part below the 1/255 cut, whose integral is 2 pi sigma^2 / 255.
  const double alpha_sum = 2 * std::numbers::pi * sigma2 * (g.opacity - 1.0 / 255);
  for (const Rendered& r : render(m)) {
    SCOPED_TRACE(r.who);
    const size_t centre = 32 * kSize + 32;
    EXPECT_NEAR(r.alpha[centre], g.opacity, r.tolerance);
    EXPECT_NEAR(r.image[centre], g.opacity * g.colour, r.tolerance);
    EXPECT_NEAR(r.depth[centre], 4.0, 10 * r.tolerance);
    // d = 1 and d = 5 px along the row, and the edge of the footprint.
    for (uint32_t d : {1u, 5u, last})
      EXPECT_NEAR(r.alpha[centre + d], g.opacity * std::exp(-double(d * d) / (2 * sigma2)), r.tolerance) << d;
    EXPECT_GT(r.alpha[centre + last], 1.0 / 255);
    EXPECT_EQ(r.alpha[centre + last + 1], 0.0) << "below 1/255: skipped";
    EXPECT_EQ(r.alpha[centre - last - 1], 0.0);
    double sum = 0;
    for (double a : r.alpha) sum += a;
    EXPECT_NEAR(sum, alpha_sum, 3e-3 * alpha_sum);
  }
  EXPECT_GT(expect_matches_everywhere({stated}), 2 * kSize * kSize - 40);
}

TEST_F(RasterizerClosedForm, OffAxisGaussianAtAKnownPixel) {
  // Centred on pixel (44, 20): u = f x / z + cx = 44.5 and v = 20.5 at z = 4 give x = 0.48, y = -0.48. Off
  // the axis the footprint is stretched along the view direction (the -f x / z^2 column of J): sigma_u^2 =
  // (f s / z)^2 (1 + (x/z)^2) + 0.3, with a cross term (f s / z)^2 (x/z)(y/z).
  const Iso stated{0.48, -0.48, 4, 0.15, 0.9, 0.4};
  const GaussianModel m = model({stated});
  const Iso g = as_stored(m, 0);
  const double k2 = std::pow(kF * g.s / g.z, 2);
  const double su2 = k2 * (1 + 0.12 * 0.12) + 0.3, cross = k2 * 0.12 * -0.12;
  for (const Rendered& r : render(m)) {
    SCOPED_TRACE(r.who);
    const size_t at = 20 * kSize + 44;
    EXPECT_NEAR(r.alpha[at], g.opacity, 1e-4) << "the peak is on pixel (44, 20)";
    EXPECT_LT(r.alpha[at + 1], r.alpha[at]);
    EXPECT_LT(r.alpha[at - 1], r.alpha[at]);
    EXPECT_LT(r.alpha[at + kSize], r.alpha[at]);
    // Three pixels right: only the u-variance and the cross term matter along the row (d = (3, 0)):
    // d^T Sigma^-1 d = 9 sigma_v^2 / det, det = sigma_u^2 sigma_v^2 - cross^2 with sigma_v^2 = su2 here.
    const double det = su2 * su2 - cross * cross;
    EXPECT_NEAR(r.alpha[at + 3], g.opacity * std::exp(-0.5 * 9 * su2 / det), 1e-4);
  }
  expect_matches_everywhere({stated});
}

TEST_F(RasterizerClosedForm, TwoLayersCompositeFrontToBack) {
  // Listed back first: the rasterizers must sort by depth. At the centre pixel both peak: a1 = 0.6, a2 = 0.7:
  // C = a1 c1 + (1 - a1) a2 c2 = 0.54 + 0.084, alpha = 1 - (1 - a1)(1 - a2) = 0.88,
  // depth = (a1 z1 + (1 - a1) a2 z2) / alpha = (1.8 + 1.4) / 0.88.
  const std::vector<Iso> stated = {{0, 0, 5, 0.3, 0.7, 0.3}, {0, 0, 3, 0.08, 0.6, 0.9}};
  const GaussianModel m = model(stated);
  const Iso back = as_stored(m, 0), front = as_stored(m, 1);
  const double a1 = front.opacity, a2 = back.opacity;
  ASSERT_NEAR(a1, 0.6, 1e-6);
  const double colour = a1 * front.colour + (1 - a1) * a2 * back.colour;
  const double alpha = 1 - (1 - a1) * (1 - a2);
  const double depth = (a1 * front.z + (1 - a1) * a2 * back.z) / alpha;
  EXPECT_NEAR(colour, 0.624, 1e-6);
  EXPECT_NEAR(alpha, 0.88, 1e-6);
  for (const Rendered& r : render(m)) {
    SCOPED_TRACE(r.who);
    const size_t centre = 32 * kSize + 32;
    EXPECT_NEAR(r.image[centre], colour, r.tolerance);
    EXPECT_NEAR(r.alpha[centre], alpha, r.tolerance);
    EXPECT_NEAR(r.depth[centre], depth, 10 * r.tolerance);
    EXPECT_NEAR(r.depth[centre], 3.2 / 0.88, 1e-5);
  }
  expect_matches_everywhere(stated);
}

TEST_F(RasterizerClosedForm, AlphaClampAndTransmittanceStop) {
  // Three wide layers on the axis (listed out of order). At the centre: the front one's 0.9999 is clamped to
  // a1 = 0.99 (T = 0.01), the second's a2 = 0.98 still leaves T = 2e-4 >= 1e-4, and the third (a3 = 0.9)
  // would take T to 2e-5 < 1e-4: the pixel stops before it. So C = 0.99 c1 + 0.01 * 0.98 c2 (the third's
  // 2e-4 * 0.9 * c3 = 1.8e-4 must be absent), alpha = 1 - 2e-4, depth = (0.99 z1 + 0.0098 z2) / alpha.
  const std::vector<Iso> stated = {
      {0, 0, 4, 0.5, 0.9, 1.0}, {0, 0, 2, 0.5, 0.9999, 0.2}, {0, 0, 3, 0.5, 0.98, 0.6}};
  const GaussianModel m = model(stated);
  const Iso g1 = as_stored(m, 1), g2 = as_stored(m, 2);
  const double a2 = g2.opacity;
  const double colour = 0.99 * g1.colour + 0.01 * a2 * g2.colour;
  const double alpha = 1 - 0.01 * (1 - a2);
  const double depth = (0.99 * g1.z + 0.01 * a2 * g2.z) / alpha;
  EXPECT_NEAR(colour, 0.198 + 0.00588, 1e-6);
  for (const Rendered& r : render(m)) {
    SCOPED_TRACE(r.who);
    const size_t centre = 32 * kSize + 32;
    EXPECT_NEAR(r.image[centre], colour, 2 * r.tolerance) << "the third layer must not be composited";
    EXPECT_NEAR(r.alpha[centre], alpha, 2 * r.tolerance);
    EXPECT_NEAR(r.depth[centre], depth, 10 * r.tolerance);
  }
  expect_matches_everywhere(stated);
}

}  // namespace
}  // namespace litgs
