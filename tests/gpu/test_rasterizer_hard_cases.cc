// Named numerical hard cases of the rasterizer: every output and gradient finite, culling counted, and
// agreement with the double-precision reference where the case is well-posed in float32.
#include <gtest/gtest.h>

#include <cmath>
#include <limits>
#include <random>
#include <string>

#include "gpu_test.h"
#include "kernels/splat/rasterizer.h"
#include "kernels/splat/reference.h"
#include "splat_scenes.h"

namespace litgs {
namespace {

using kernels::DeviceGaussians;
using kernels::GaussianModel;
using kernels::Rasterizer;
using kernels::SplatCamera;

GaussianModel one_gaussian(float x, float y, float z, float log_scale, float logit = 1.0f) {
  GaussianModel m;
  m.channels = 1;
  m.sh_degree = 3;
  m.resize(1);
  m.means = {x, y, z};
  m.log_scales = {log_scale, log_scale, log_scale};
  m.quats = {1.0f, 0.0f, 0.0f, 0.0f};
  m.opacity_logits = {logit};
  m.sh[0] = 1.0f;
  return m;
}

void append(GaussianModel& dst, const GaussianModel& src) {
  dst.means.insert(dst.means.end(), src.means.begin(), src.means.end());
  dst.log_scales.insert(dst.log_scales.end(), src.log_scales.begin(), src.log_scales.end());
  dst.quats.insert(dst.quats.end(), src.quats.begin(), src.quats.end());
  dst.opacity_logits.insert(dst.opacity_logits.end(), src.opacity_logits.begin(), src.opacity_logits.end());
  dst.sh.insert(dst.sh.end(), src.sh.begin(), src.sh.end());
}

template <class T>
void expect_all_finite(const std::vector<T>& v, const std::string& name) {
  for (size_t i = 0; i < v.size(); ++i)
    ASSERT_TRUE(std::isfinite(static_cast<double>(v[i]))) << name << "[" << i << "]";
}

struct Outcome {
  kernels::RenderImages<float> images;
  kernels::GaussianGrads<float> grads;
};

class RasterizerHardCase : public testing::GpuTest {
 protected:
  // Forward and backward with random upstream gradients; asserts finiteness everywhere, and that exactly
  // `nonfinite` Gaussians were culled as non-finite (their count of non-finite parameters: a degenerate but
  // finite Gaussian is not one). With `compare_reference`, the forward must also agree with the reference
  // within 1e-4 on 99.5% of values, and count the same.
  Outcome run(const GaussianModel& model, const SplatCamera& camera, bool compare_reference = true,
              uint32_t nonfinite = 0) {
    DeviceGaussians g(context(), model);
    Rasterizer r(context(), model.channels);
    r.forward(g, camera);
    Outcome o;
    o.images = r.download_images();
    kernels::RenderGradInput grad;
    std::mt19937 rng(1);
    std::uniform_real_distribution<float> u(-1.0f, 1.0f);
    grad.image.resize(o.images.image.size());
    grad.depth.resize(o.images.depth.size());
    grad.alpha.resize(o.images.alpha.size());
    for (auto& x : grad.image) x = u(rng);
    for (auto& x : grad.depth) x = u(rng);
    for (auto& x : grad.alpha) x = u(rng);
    r.backward(grad);
    o.grads = r.download_grads();
    expect_all_finite(o.images.image, "image");
    expect_all_finite(o.images.depth, "depth");
    expect_all_finite(o.images.alpha, "alpha");
    expect_all_finite(o.grads.means, "grad means");
    expect_all_finite(o.grads.log_scales, "grad log_scales");
    expect_all_finite(o.grads.quats, "grad quats");
    expect_all_finite(o.grads.opacity_logits, "grad opacity_logits");
    expect_all_finite(o.grads.sh, "grad sh");
    expect_all_finite(o.grads.means2d, "grad means2d");
    EXPECT_EQ(o.images.culled_nonfinite, nonfinite);
    if (compare_reference) {
      const auto want = kernels::reference_forward(model, camera);
      EXPECT_EQ(want.culled_nonfinite, nonfinite);
      EXPECT_EQ(o.images.intersections, want.intersections);
      EXPECT_GE(testing::compare(o.images.image, want.image, 1e-4).fraction_within, 0.995);
      EXPECT_GE(testing::compare(o.images.alpha, want.alpha, 1e-4).fraction_within, 0.995);
      EXPECT_GE(testing::compare(o.images.depth, want.depth, 1e-3).fraction_within, 0.995);
    }
    return o;
  }
};

const SplatCamera kCamera = testing::camera_looking_down_z(64, 48);

double sum(const std::vector<float>& v) {
  double s = 0;
  for (float x : v) s += x;
  return s;
}

TEST_F(RasterizerHardCase, FlatGaussian) {
  auto m = one_gaussian(0.1f, 0.0f, 3.0f, -2.0f);
  m.log_scales[2] = std::log(1e-8f);
  const auto o = run(m, kCamera);
  EXPECT_GT(sum(o.images.alpha), 1.0) << "a flat disc facing the camera is visible";
}

TEST_F(RasterizerHardCase, Needle) {
  auto m = one_gaussian(0.0f, 0.0f, 3.0f, std::log(1e-6f));
  m.log_scales[0] = 0.0f;  // 1 m long, a micrometre thin
  m.quats = {0.9f, 0.1f, 0.3f, 0.2f};
  run(m, kCamera);
}

TEST_F(RasterizerHardCase, OneGaussianCoversWholeImage) {
  const auto o = run(one_gaussian(0.0f, 0.0f, 2.0f, 1.5f, 2.0f), kCamera);
  for (float a : o.images.alpha) EXPECT_GT(a, 0.5f);
  EXPECT_EQ(o.images.intersections, 4u * 3u) << "every tile of a 64x48 image";
}

TEST_F(RasterizerHardCase, BehindCamera) {
  const auto o = run(one_gaussian(0.0f, 0.0f, -3.0f, -1.0f), kCamera);
  EXPECT_EQ(o.images.intersections, 0u);
  EXPECT_EQ(sum(o.images.alpha), 0.0);
  for (float g : o.grads.means) EXPECT_EQ(g, 0.0f);
}

TEST_F(RasterizerHardCase, StraddlesNearPlane) {
  // Centre just behind the near plane with an extent reaching in front of it: culled by its centre.
  auto behind = one_gaussian(0.0f, 0.0f, 0.009f, -3.0f);
  // Centre just in front: a huge footprint, still finite.
  append(behind, one_gaussian(0.001f, 0.0f, 0.011f, -5.0f));
  run(behind, kCamera);
}

TEST_F(RasterizerHardCase, AtImageBorder) {
  GaussianModel m = one_gaussian(-0.5f * 3.0f, -0.5f * 3.0f * 48.0f / 64.0f, 3.0f, -2.5f);  // image corner
  append(m, one_gaussian(0.5f * 3.0f + 0.05f, 0.0f, 3.0f, -2.0f));                   // just outside right
  append(m, one_gaussian(0.0f, 0.5f * 3.0f * 48.0f / 64.0f - 0.001f, 3.0f, -2.5f));  // bottom edge
  const auto o = run(m, kCamera);
  EXPECT_GT(o.images.intersections, 0u);
}

TEST_F(RasterizerHardCase, OpacityNearZeroAndNearOne) {
  GaussianModel m = one_gaussian(0.0f, 0.0f, 3.0f, -1.5f, -12.0f);  // alpha < 1/255: culled
  // On a pixel centre, so that alpha reaches the 0.99 clamp there.
  append(m, one_gaussian(0.21875f, 0.03125f, 4.0f, -1.5f, 12.0f));
  const auto o = run(m, kCamera);
  EXPECT_EQ(o.grads.opacity_logits[0], 0.0f);
  float max_alpha = 0;
  for (float a : o.images.alpha) max_alpha = std::max(max_alpha, a);
  EXPECT_NEAR(max_alpha, 0.99f, 1e-5f);
}

TEST_F(RasterizerHardCase, TenThousandAtExactlyTheSameDepth) {
  GaussianModel m;
  m.channels = 1;
  m.sh_degree = 0;
  std::mt19937 rng(5);
  std::uniform_real_distribution<float> u(-1.0f, 1.0f);
  for (int i = 0; i < 10000; ++i) {
    auto g = one_gaussian(1.4f * u(rng), 1.0f * u(rng), 3.0f, -3.5f, -1.0f);
    g.sh_degree = 0;
    g.sh = {0.5f + 0.5f * u(rng)};
    append(m, g);
  }
  SplatCamera c = kCamera;
  c.sh_degree = 0;
  const auto o = run(m, c);
  EXPECT_GT(o.images.intersections, 10000u);
}

TEST_F(RasterizerHardCase, NonFiniteParametersAreCulledAndCounted) {
  const float nan = std::numeric_limits<float>::quiet_NaN(), inf = std::numeric_limits<float>::infinity();
  GaussianModel m = one_gaussian(0.0f, 0.0f, 3.0f, -1.5f);  // a good one
  auto bad = [&](int field) {
    auto g = one_gaussian(0.1f, 0.1f, 3.0f, -1.5f);
    if (field == 0) g.means[0] = nan;
    if (field == 1) g.log_scales[1] = inf;
    if (field == 2) g.quats[2] = nan;
    if (field == 3) g.opacity_logits[0] = nan;
    if (field == 4) g.sh[5] = -inf;
    return g;
  };
  for (int f = 0; f < 5; ++f) append(m, bad(f));
  const auto o = run(m, kCamera, true, 5);
  EXPECT_GT(sum(o.images.alpha), 1.0);
  // The culled rows get zero gradients, and the render is the good Gaussian's alone, bit for bit.
  for (size_t i = 1; i < 6; ++i) {
    for (int a = 0; a < 3; ++a) EXPECT_EQ(o.grads.means[3 * i + a], 0.0f) << i;
    for (int a = 0; a < 3; ++a) EXPECT_EQ(o.grads.log_scales[3 * i + a], 0.0f) << i;
    for (int a = 0; a < 4; ++a) EXPECT_EQ(o.grads.quats[4 * i + a], 0.0f) << i;
    EXPECT_EQ(o.grads.opacity_logits[i], 0.0f) << i;
    for (size_t k = 0; k < m.sh_coeffs(); ++k) EXPECT_EQ(o.grads.sh[i * m.sh_coeffs() + k], 0.0f) << i;
  }
  const auto alone = run(one_gaussian(0.0f, 0.0f, 3.0f, -1.5f), kCamera);
  EXPECT_EQ(o.images.image, alone.images.image);
  EXPECT_EQ(o.images.alpha, alone.images.alpha);
  EXPECT_EQ(o.images.depth, alone.images.depth);
  EXPECT_EQ(o.images.intersections, alone.images.intersections);
}

TEST_F(RasterizerHardCase, ZeroQuaternion) {
  auto m = one_gaussian(0.0f, 0.0f, 3.0f, -1.5f);
  m.quats = {0.0f, 0.0f, 0.0f, 0.0f};
  const auto o = run(m, kCamera);
  for (float g : o.grads.quats) EXPECT_EQ(g, 0.0f);
  EXPECT_GT(sum(o.images.alpha), 1.0);
}

TEST_F(RasterizerHardCase, SceneOneKilometreFromOrigin) {
  auto m = testing::random_scene(200, 1, 3, 61);
  for (size_t i = 0; i < m.size(); ++i) {
    m.means[3 * i] += 1000.0f;
    m.means[3 * i + 1] -= 1000.0f;
    m.means[3 * i + 2] += 1000.0f;
  }
  SplatCamera c = kCamera;
  c.t_cam_world = glm::dvec3(-1000.0, 1000.0, -1000.0);
  // float32 holds 1000 m to 61 micrometres: compare with the reference at a tolerance that allows it.
  const auto o = run(m, c, /*compare_reference=*/false);
  const auto want = kernels::reference_forward(m, c);
  EXPECT_GE(testing::compare(o.images.alpha, want.alpha, 5e-3).fraction_within, 0.99);
}

TEST_F(RasterizerHardCase, ImageSizes) {
  const auto m = testing::random_scene(300, 1, 3, 71);
  for (auto [w, h] : {std::pair{1u, 1u}, std::pair{17u, 13u}, std::pair{640u, 512u}}) {
    SCOPED_TRACE(std::to_string(w) + "x" + std::to_string(h));
    run(m, testing::camera_looking_down_z(w, h));
  }
}

TEST_F(RasterizerHardCase, EmptyModel) {
  GaussianModel m;
  m.channels = 1;
  m.sh_degree = 3;
  const auto o = run(m, kCamera);
  EXPECT_EQ(o.images.intersections, 0u);
  EXPECT_EQ(sum(o.images.image), 0.0);
}

}  // namespace
}  // namespace litgs
