// The loss kernels against their double-precision references (kernels/loss/loss_reference.h), validation
// layer on. Tolerances (float kernels against double references):
//   photometric loss, mean SSIM, mean L1: |device - reference| <= 2e-6 + 2e-5 |reference|; on constant
//     images 1e-4 (zero variance: sigma^2 = E[x^2] - mu^2 cancels in float32 to ~1e-8 against C2 = 9e-4)
//   photometric gradient: max_i |device_i - reference_i| <= 1e-4 * weight * max(max_i |reference_i|, 1/N),
//     1/N being the scale of the L1 term's gradient (N = C*H*W)
//   geometric loss: relative 1e-5; geometric gradient: max abs error <= 1e-5 max |reference|
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstring>
#include <limits>
#include <random>
#include <string>
#include <vector>

#include "engine/buffer.h"
#include "engine/sequence.h"
#include "gpu_test.h"
#include "kernels/loss/geometric_loss.h"
#include "kernels/loss/loss_reference.h"
#include "kernels/loss/photometric_loss.h"

namespace litgs {
namespace {

using engine::DeviceArray;
using kernels::GeometricLoss;
using kernels::PhotometricLoss;
using kernels::PhotometricLossOptions;

constexpr float kSentinel = -12345.0f;
constexpr uint32_t kSlot = 2;  // outputs land at loss_out[2..]; the slots around must stay untouched
constexpr uint32_t kLossFloats = 8;

std::vector<float> random_image(size_t n, uint32_t seed, float lo = 0.0f, float hi = 1.0f) {
  std::mt19937 rng(seed);
  std::uniform_real_distribution<float> u(lo, hi);
  std::vector<float> v(n);
  for (auto& x : v) x = u(rng);
  return v;
}

std::vector<double> to_double(const std::vector<float>& v) {
  return {v.begin(), v.end()};
}

double max_abs(const std::vector<double>& v) {
  double m = 0.0;
  for (double x : v) m = std::max(m, std::abs(x));
  return m;
}

template <class A, class B>
double max_abs_diff(const std::vector<A>& a, const std::vector<B>& b, double scale_b = 1.0) {
  double m = 0.0;
  for (size_t i = 0; i < a.size(); ++i)
    m = std::max(m, std::abs(static_cast<double>(a[i]) - scale_b * static_cast<double>(b[i])));
  return m;
}

void expect_finite(const std::vector<float>& v, const char* what) {
  for (size_t i = 0; i < v.size(); ++i) ASSERT_TRUE(std::isfinite(v[i])) << what << "[" << i << "]";
}

struct PhotoOut {
  float loss = 0, ssim = 0, l1 = 0;
  std::vector<float> grad;
  std::vector<float> loss_buffer;
};

class LossTest : public testing::GpuTest {
 protected:
  PhotoOut run_photometric(PhotometricLoss& loss, const std::vector<float>& x, const std::vector<float>& y,
                           uint32_t w, uint32_t h, float weight) {
    DeviceArray<float> image(context(), "test: image", x.size()), target(context(), "test: target", y.size());
    DeviceArray<float> grad(context(), "test: grad", x.size());
    DeviceArray<float> out(context(), "test: loss out", kLossFloats);
    image.upload(x);
    target.upload(y);
    grad.upload(std::vector<float>(x.size(), kSentinel));  // overwritten, not accumulated
    out.upload(std::vector<float>(kLossFloats, kSentinel));
    engine::Sequence seq(context());
    loss.record(seq, image.buffer(), target.buffer(), w, h, weight, grad.buffer(), out.buffer(), kSlot);
    seq.submit_and_wait();
    PhotoOut r;
    r.loss_buffer = out.download();
    r.loss = r.loss_buffer[kSlot];
    r.ssim = r.loss_buffer[kSlot + 1];
    r.l1 = r.loss_buffer[kSlot + 2];
    r.grad = grad.download();
    for (uint32_t i = 0; i < kLossFloats; ++i)
      if (i < kSlot || i >= kSlot + PhotometricLoss::kOutputs) {
        EXPECT_EQ(r.loss_buffer[i], kSentinel) << "slot " << i;
      }
    return r;
  }

  // Device against reference with the stated tolerances; returns the reference.
  kernels::PhotometricLossResult compare_photometric(uint32_t c, uint32_t w, uint32_t h,
                                                     const std::vector<float>& x, const std::vector<float>& y,
                                                     double value_tol = -1.0, float lambda = 0.2f,
                                                     float weight = 0.4f) {
    PhotometricLossOptions options;
    options.lambda_ssim = lambda;
    PhotometricLoss loss(context(), c, options);
    const PhotoOut d = run_photometric(loss, x, y, w, h, weight);
    const auto ref = kernels::photometric_loss_reference(to_double(x), to_double(y), c, w, h, lambda);
    expect_finite(d.grad, "grad");
    const std::string where = std::to_string(c) + "x" + std::to_string(w) + "x" + std::to_string(h);
    auto tol = [&](double v) { return value_tol >= 0 ? value_tol : 2e-6 + 2e-5 * std::abs(v); };
    EXPECT_NEAR(d.loss, ref.loss, tol(ref.loss)) << where;
    EXPECT_NEAR(d.ssim, ref.mean_ssim, tol(ref.mean_ssim)) << where;
    EXPECT_NEAR(d.l1, ref.mean_l1, tol(ref.mean_l1)) << where;
    const double n = double(c) * w * h;
    const double scale = std::max(max_abs(ref.grad), 1.0 / n) * weight;
    const double err = max_abs_diff(d.grad, ref.grad, weight);
    EXPECT_LE(err, 1e-4 * scale) << where << ": max |grad error| " << err << " against max |grad| " << scale;
    std::printf("[ stats    ] %s loss %.3g (err %.2g) ssim err %.2g, grad err / max %.2g\n", where.c_str(),
                ref.loss, std::abs(d.loss - ref.loss), std::abs(d.ssim - ref.mean_ssim), err / scale);
    return ref;
  }
};

TEST_F(LossTest, PhotometricMatchesReferenceOnePixel) {
  compare_photometric(1, 1, 1, {0.3f}, {0.7f});
}
TEST_F(LossTest, PhotometricMatchesReference17x13) {
  compare_photometric(1, 17, 13, random_image(17 * 13, 1), random_image(17 * 13, 2));
}
TEST_F(LossTest, PhotometricMatchesReference320x256) {
  compare_photometric(1, 320, 256, random_image(320 * 256, 3), random_image(320 * 256, 4));
}
TEST_F(LossTest, PhotometricMatchesReference640x512) {
  compare_photometric(1, 640, 512, random_image(640 * 512, 5), random_image(640 * 512, 6));
}
TEST_F(LossTest, PhotometricMatchesReferenceThreeChannels) {
  compare_photometric(3, 17, 13, random_image(3 * 17 * 13, 7), random_image(3 * 17 * 13, 8));
  compare_photometric(3, 320, 256, random_image(3 * 320 * 256, 9), random_image(3 * 320 * 256, 10));
}
TEST_F(LossTest, PhotometricMatchesReferenceOnSmoothImages) {
  // Random pixels make SSIM small; a smooth image near its target is the regime training lives in.
  const uint32_t w = 96, h = 80;
  std::vector<float> x(w * h), y(w * h);
  for (uint32_t j = 0; j < h; ++j)
    for (uint32_t i = 0; i < w; ++i) {
      const float fi = static_cast<float>(i), fj = static_cast<float>(j);
      y[j * w + i] = 0.5f + 0.3f * std::sin(0.1f * fi) * std::cos(0.13f * fj);
      x[j * w + i] = y[j * w + i] + 0.02f * std::sin(0.7f * fi + 0.3f * fj);
    }
  const auto ref = compare_photometric(1, w, h, x, y);
  EXPECT_GT(ref.mean_ssim, 0.8);
}

TEST_F(LossTest, PhotometricIdenticalImages) {
  const uint32_t c = 3, w = 37, h = 29;
  const auto x = random_image(size_t{c} * w * h, 11);
  PhotometricLoss loss(context(), c);
  const PhotoOut d = run_photometric(loss, x, x, w, h, 1.0f);
  EXPECT_NEAR(d.loss, 0.0f, 1e-6f);
  EXPECT_NEAR(d.ssim, 1.0f, 1e-6f);
  EXPECT_EQ(d.l1, 0.0f);
  // Gradients are O(1/N); at the minimum they vanish up to rounding.
  const double n = double(c) * w * h;
  for (size_t i = 0; i < d.grad.size(); ++i) ASSERT_LE(std::abs(d.grad[i]) * n, 1e-4) << i;
}

TEST_F(LossTest, PhotometricConstantImages) {
  const uint32_t w = 40, h = 24;
  compare_photometric(1, w, h, std::vector<float>(w * h, 0.3f), std::vector<float>(w * h, 0.7f), 1e-4);
  compare_photometric(1, w, h, std::vector<float>(w * h, 0.5f), std::vector<float>(w * h, 0.5f), 1e-4);
  compare_photometric(3, w, h, std::vector<float>(3 * w * h, 0.9f), std::vector<float>(3 * w * h, 0.1f),
                      1e-4);
}

TEST_F(LossTest, PhotometricTargetAllZeros) {
  const uint32_t w = 33, h = 21;
  compare_photometric(1, w, h, random_image(w * h, 12), std::vector<float>(w * h, 0.0f));
  compare_photometric(1, w, h, std::vector<float>(w * h, 0.0f), std::vector<float>(w * h, 0.0f));
}

TEST_F(LossTest, PhotometricTinyNoise) {
  const uint32_t w = 64, h = 48;
  const auto y = random_image(w * h, 13);
  auto x = y;
  const auto noise = random_image(w * h, 14, -1e-4f, 1e-4f);
  for (size_t i = 0; i < x.size(); ++i) x[i] += noise[i];
  compare_photometric(1, w, h, x, y);
}

TEST_F(LossTest, PhotometricLambdaZeroIsExactlyL1) {
  const uint32_t c = 3, w = 29, h = 17;
  const auto x = random_image(size_t{c} * w * h, 15), y = random_image(size_t{c} * w * h, 16);
  PhotometricLossOptions options;
  options.lambda_ssim = 0.0f;
  PhotometricLoss loss(context(), c, options);
  const float weight = 0.4f;
  const PhotoOut d = run_photometric(loss, x, y, w, h, weight);
  EXPECT_EQ(d.loss, d.l1);  // bit for bit: the SSIM sum enters with weight 0
  const auto ref = kernels::photometric_loss_reference(to_double(x), to_double(y), c, w, h, 0.0);
  EXPECT_NEAR(d.loss, ref.mean_l1, 1e-6);
  const float inv_n = static_cast<float>(1.0 / (double(c) * w * h));
  for (size_t i = 0; i < x.size(); ++i) {
    const float sign = x[i] > y[i] ? 1.0f : x[i] < y[i] ? -1.0f : 0.0f;
    ASSERT_EQ(d.grad[i], weight * (inv_n * sign)) << i;
  }
}

TEST_F(LossTest, PhotometricIsDeterministicAndScratchIsReused) {
  const uint32_t w = 100, h = 70;
  const auto x = random_image(w * h, 17), y = random_image(w * h, 18);
  PhotometricLoss loss(context(), 1);
  const PhotoOut a = run_photometric(loss, x, y, w, h, 1.0f);
  // A smaller image in between: the scratch is reused, not regrown; then the first again, bit for bit.
  run_photometric(loss, random_image(7 * 5, 19), random_image(7 * 5, 20), 7, 5, 1.0f);
  const PhotoOut b = run_photometric(loss, x, y, w, h, 1.0f);
  EXPECT_EQ(std::memcmp(a.loss_buffer.data(), b.loss_buffer.data(), kLossFloats * sizeof(float)), 0);
  EXPECT_EQ(std::memcmp(a.grad.data(), b.grad.data(), a.grad.size() * sizeof(float)), 0);
}

TEST_F(LossTest, PhotometricRejectsBadArguments) {
  EXPECT_THROW(PhotometricLoss(context(), 0), std::invalid_argument);
  EXPECT_THROW(PhotometricLoss(context(), 5), std::invalid_argument);
  PhotometricLossOptions bad;
  bad.lambda_ssim = 1.5f;
  EXPECT_THROW(PhotometricLoss(context(), 1, bad), std::invalid_argument);
  PhotometricLoss loss(context(), 3);
  DeviceArray<float> small(context(), "test: small", 10), out(context(), "test: out", 3);
  DeviceArray<float> big(context(), "test: big", 3 * 4 * 4);
  engine::Sequence seq(context());
  // A one-channel-sized image for a three-channel loss.
  EXPECT_THROW(loss.record(seq, small.buffer(), big.buffer(), 4, 4, 1.0f, big.buffer(), out.buffer(), 0),
               std::invalid_argument);
  EXPECT_THROW(loss.record(seq, big.buffer(), big.buffer(), 4, 4, 1.0f, big.buffer(), out.buffer(), 1),
               std::invalid_argument);  // slots 1..3 do not fit in 3 floats
  EXPECT_THROW(loss.record(seq, big.buffer(), big.buffer(), 0, 4, 1.0f, big.buffer(), out.buffer(), 0),
               std::invalid_argument);
  EXPECT_EQ(seq.dispatch_count(), 0u);
}

// ---- Geometric ----

struct GeoScene {
  uint32_t w = 0, h = 0;
  float fx = 0, fy = 0, cx = 0, cy = 0;
  std::vector<float> depth, points, normals;
  uint32_t valid = 0;
};

// Planes seen by a pinhole camera: random points near the rendered depth, every 5th pixel without a point,
// every 7th pixel with nothing rendered.
GeoScene random_geo_scene(uint32_t w, uint32_t h, uint32_t seed) {
  GeoScene s;
  s.w = w;
  s.h = h;
  s.fx = 0.8f * static_cast<float>(w);
  s.fy = s.fx;
  s.cx = 0.5f * static_cast<float>(w) - 0.3f;
  s.cy = 0.5f * static_cast<float>(h) + 0.2f;
  std::mt19937 rng(seed);
  std::uniform_real_distribution<float> u(-1.0f, 1.0f);
  const size_t n = size_t{w} * h;
  s.depth.resize(n);
  s.points.assign(4 * n, 0.0f);
  s.normals.assign(4 * n, 0.0f);
  for (size_t i = 0; i < n; ++i) {
    s.depth[i] = 5.0f + 2.0f * u(rng);
    if (i % 7 == 3) s.depth[i] = 0.0f;
    if (i % 5 == 1) continue;
    const float z = s.depth[i] + 0.2f * u(rng);
    const float px = ((static_cast<float>(i % w) + 0.5f - s.cx) / s.fx) * z;
    const float py = ((static_cast<float>(i / w) + 0.5f - s.cy) / s.fy) * z;
    const float nx = 0.3f * u(rng), ny = 0.3f * u(rng), nz = -1.0f,
                len = std::sqrt(nx * nx + ny * ny + nz * nz);
    s.points[4 * i + 0] = px + 0.05f * u(rng);
    s.points[4 * i + 1] = py + 0.05f * u(rng);
    s.points[4 * i + 2] = z;
    s.points[4 * i + 3] = 1.0f;
    s.normals[4 * i + 0] = nx / len;
    s.normals[4 * i + 1] = ny / len;
    s.normals[4 * i + 2] = nz / len;
  }
  s.valid = GeometricLoss::count_valid(s.points);
  return s;
}

struct GeoOut {
  float loss = 0, counted = 0;
  std::vector<float> grad;
};

class GeometricLossTest : public testing::GpuTest {
 protected:
  GeoOut run(GeometricLoss& loss, const GeoScene& s, float weight, uint32_t valid_count,
             float robust_scale = 0.0f) {
    const size_t n = size_t{s.w} * s.h;
    // The kernel takes the packed targets; the reference the point and normal maps they come from.
    const std::vector<float> packed = GeometricLoss::pack_plane_targets(s.points, s.normals);
    EXPECT_EQ(GeometricLoss::count_valid_planes(packed), GeometricLoss::count_valid(s.points));
    DeviceArray<float> depth(context(), "test: depth", n), planes(context(), "test: plane targets", 4 * n),
        grad(context(), "test: grad depth", n), out(context(), "test: loss out", kLossFloats);
    depth.upload(s.depth);
    planes.upload(packed);
    grad.upload(std::vector<float>(n, kSentinel));
    out.upload(std::vector<float>(kLossFloats, kSentinel));
    engine::Sequence seq(context());
    loss.record(seq, depth.buffer(), planes.buffer(), s.w, s.h, s.fx, s.fy, s.cx, s.cy, valid_count, weight,
                robust_scale, grad.buffer(), out.buffer(), kSlot);
    seq.submit_and_wait();
    const auto o = out.download();
    for (uint32_t i = 0; i < kLossFloats; ++i)
      if (i < kSlot || i >= kSlot + GeometricLoss::kOutputs) {
        EXPECT_EQ(o[i], kSentinel) << "slot " << i;
      }
    GeoOut r{o[kSlot], o[kSlot + 1], grad.download()};
    expect_finite(r.grad, "grad depth");
    return r;
  }

  void compare(const GeoScene& s, float weight = 0.6f, float robust_scale = 0.0f) {
    GeometricLoss loss(context());
    const GeoOut d = run(loss, s, weight, s.valid, robust_scale);
    const auto ref = kernels::geometric_loss_reference(to_double(s.depth), s.points, s.normals, s.w, s.h,
                                                       s.fx, s.fy, s.cx, s.cy, s.valid, robust_scale);
    const std::string where =
        std::to_string(s.w) + "x" + std::to_string(s.h) + " robust scale " + std::to_string(robust_scale);
    EXPECT_NEAR(d.loss, ref.loss, 1e-5 * ref.loss + 1e-12) << where;
    EXPECT_EQ(d.counted, static_cast<float>(ref.counted)) << where;
    const double scale = max_abs(ref.grad_depth) * weight;
    const double err = max_abs_diff(d.grad, ref.grad_depth, weight);
    // The float residual carries ~1e-6 m of rounding at these 3-7 m depths; the Cauchy gradient peaks at
    // |r| = s, so relative to its peak the rounding weighs 1e-6 m / s.
    const double tolerance = robust_scale > 0 ? std::max(1e-5, 2e-6 / robust_scale) : 1e-5;
    EXPECT_LE(err, tolerance * scale)
        << where << ": max |grad error| " << err << " against max |grad| " << scale;
    for (size_t i = 0; i < s.depth.size(); ++i)
      if (s.depth[i] == 0.0f || s.points[4 * i + 3] == 0.0f) {
        ASSERT_EQ(d.grad[i], 0.0f) << where << " pixel " << i;
      }
    std::printf("[ stats    ] geo %s loss %.4g rel err %.2g, grad err / max %.2g\n", where.c_str(), ref.loss,
                std::abs(d.loss - ref.loss) / ref.loss, err / scale);
  }
};

TEST_F(GeometricLossTest, MatchesReferenceOnePixel) {
  GeoScene s = random_geo_scene(1, 1, 1);
  compare(s);
}
TEST_F(GeometricLossTest, MatchesReference17x13) {
  compare(random_geo_scene(17, 13, 2));
}
TEST_F(GeometricLossTest, MatchesReference320x256) {
  compare(random_geo_scene(320, 256, 3));
}
TEST_F(GeometricLossTest, MatchesReference640x512) {
  compare(random_geo_scene(640, 512, 4));
}
TEST_F(GeometricLossTest, CauchyKernelMatchesReference) {
  // Residuals up to ~0.3 m against scales below, at and above them: both branches of the kernel's value.
  for (const float scale : {0.01f, 0.05f, 1.0f, 100.0f}) compare(random_geo_scene(64, 48, 9), 0.6f, scale);
}

TEST_F(GeometricLossTest, NoLidarPoints) {
  GeoScene s = random_geo_scene(31, 19, 5);
  for (size_t i = 3; i < s.points.size(); i += 4) s.points[i] = 0.0f;
  ASSERT_EQ(GeometricLoss::count_valid(s.points), 0u);
  GeometricLoss loss(context());
  const GeoOut d = run(loss, s, 0.6f, 0);
  EXPECT_EQ(d.loss, 0.0f);
  EXPECT_EQ(d.counted, 0.0f);
  for (float g : d.grad) ASSERT_EQ(g, 0.0f);
  // valid_count 0 with points present (a caller's choice to switch the term off): still 0.
  GeoScene t = random_geo_scene(31, 19, 6);
  const GeoOut e = run(loss, t, 0.6f, 0);
  EXPECT_EQ(e.loss, 0.0f);
  for (float g : e.grad) ASSERT_EQ(g, 0.0f);
}

TEST_F(GeometricLossTest, DepthZeroPixelsAreSkipped) {
  GeoScene s = random_geo_scene(23, 17, 7);
  for (size_t i = 0; i < s.depth.size(); i += 2) s.depth[i] = 0.0f;  // half the view rendered nothing
  compare(s);
  // Nothing rendered at all: loss 0, zero gradient, N_valid unchanged.
  std::fill(s.depth.begin(), s.depth.end(), 0.0f);
  GeometricLoss loss(context());
  const GeoOut d = run(loss, s, 0.6f, s.valid);
  EXPECT_EQ(d.loss, 0.0f);
  EXPECT_EQ(d.counted, 0.0f);
  for (float g : d.grad) ASSERT_EQ(g, 0.0f);
}

TEST_F(GeometricLossTest, ExactPlaneHasZeroLossAndGradient) {
  // Points on the rendered surface itself: residual 0 up to float rounding.
  GeoScene s = random_geo_scene(19, 11, 8);
  for (size_t i = 0; i < s.depth.size(); ++i) {
    if (s.points[4 * i + 3] == 0.0f || s.depth[i] == 0.0f) continue;
    const float d = s.depth[i];
    s.points[4 * i + 0] = ((static_cast<float>(i % s.w) + 0.5f - s.cx) / s.fx) * d;
    s.points[4 * i + 1] = ((static_cast<float>(i / s.w) + 0.5f - s.cy) / s.fy) * d;
    s.points[4 * i + 2] = d;
  }
  GeometricLoss loss(context());
  const GeoOut r = run(loss, s, 1.0f, s.valid);
  EXPECT_LT(r.loss, 1e-10f);
  for (float g : r.grad) ASSERT_LT(std::abs(g), 1e-5f);
}

TEST_F(GeometricLossTest, PackedTargetsHoldTheNormalAndTheOffsetAlongIt) {
  // Two pixels: a point 5 m ahead on a tilted plane, and one without a point (its normal would be ignored).
  const float n = 1.0f / std::sqrt(2.0f);
  const std::vector<float> points = {0.5f, -0.25f, 5.0f, 1.0f, 1.0f, 2.0f, 3.0f, 0.0f};
  const std::vector<float> normals = {n, 0.0f, -n, 0.0f, 0.0f, 0.0f, 1.0f, 0.0f};
  const std::vector<float> packed = GeometricLoss::pack_plane_targets(points, normals);
  ASSERT_EQ(packed.size(), 8u);
  EXPECT_FLOAT_EQ(packed[0], n);
  EXPECT_FLOAT_EQ(packed[2], -n);
  EXPECT_FLOAT_EQ(packed[3], static_cast<float>((0.5 - 5.0) / std::sqrt(2.0)));
  for (size_t k = 4; k < 8; ++k) EXPECT_EQ(packed[k], 0.0f) << k;
  EXPECT_EQ(GeometricLoss::count_valid_planes(packed), 1u);
  EXPECT_THROW(GeometricLoss::pack_plane_targets(points, std::span(normals).first(4)), std::invalid_argument);
}

TEST_F(GeometricLossTest, RejectsBadArguments) {
  GeometricLoss loss(context());
  DeviceArray<float> a(context(), "test: a", 16), b(context(), "test: b", 64), out(context(), "test: out", 2);
  engine::Sequence seq(context());
  // plane targets too small for 4x4.
  EXPECT_THROW(
      loss.record(seq, a.buffer(), a.buffer(), 4, 4, 1, 1, 2, 2, 1, 1, 0, a.buffer(), out.buffer(), 0),
      std::invalid_argument);
  // valid_count above the pixel count.
  EXPECT_THROW(
      loss.record(seq, a.buffer(), b.buffer(), 4, 4, 1, 1, 2, 2, 17, 1, 0, a.buffer(), out.buffer(), 0),
      std::invalid_argument);
  // fx = 0.
  EXPECT_THROW(
      loss.record(seq, a.buffer(), b.buffer(), 4, 4, 0, 1, 2, 2, 1, 1, 0, a.buffer(), out.buffer(), 0),
      std::invalid_argument);
  // a negative or NaN robust scale.
  for (const float bad : {-0.1f, std::numeric_limits<float>::quiet_NaN()})
    EXPECT_THROW(
        loss.record(seq, a.buffer(), b.buffer(), 4, 4, 1, 1, 2, 2, 1, 1, bad, a.buffer(), out.buffer(), 0),
        std::invalid_argument);
  // slot 1 needs 3 floats.
  EXPECT_THROW(
      loss.record(seq, a.buffer(), b.buffer(), 4, 4, 1, 1, 2, 2, 1, 1, 0, a.buffer(), out.buffer(), 1),
      std::invalid_argument);
  EXPECT_EQ(seq.dispatch_count(), 0u);
}

}  // namespace
}  // namespace litgs
