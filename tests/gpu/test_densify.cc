// Adaptive density control on the device against its CPU reference (kernels/densify/densify_reference.h),
// and hand-built cases for each rule.
#include <gtest/gtest.h>

#include <cmath>
#include <cstring>
#include <limits>
#include <random>
#include <vector>

#include "gpu_test.h"
#include "kernels/densify/densify_reference.h"
#include "kernels/optim/trainable_gaussians.h"
#include "kernels/splat/reference.h"
#include "kernels/splat/splat_math.h"
#include "splat_scenes.h"

namespace litgs::kernels {
namespace {

using engine::DeviceArray;
using testing::GpuTest;

class DensifyTest : public GpuTest {};

constexpr float kExtent = 1.0f;  // clone up to 0.01, world prune above 0.1

uint32_t bits(float x) {
  uint32_t b;
  std::memcpy(&b, &x, 4);
  return b;
}

// Bitwise equality of everything except means (split children: float vs double sampling, 1e-5 relative).
void expect_states_match(const TrainingState& got, const TrainingState& want) {
  ASSERT_EQ(got.size(), want.size());
  for (uint32_t g = 0; g < kParamGroupCount; ++g) {
    const auto& a = group_values(got.model, g);
    const auto& b = group_values(want.model, g);
    ASSERT_EQ(a.size(), b.size());
    for (size_t j = 0; j < a.size(); ++j) {
      if (g == kMeans)
        ASSERT_NEAR(a[j], b[j], 1e-5 * std::max(1.0f, std::abs(b[j]))) << "mean value " << j;
      else
        ASSERT_EQ(bits(a[j]), bits(b[j])) << kParamGroupNames[g] << " value " << j;
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

void expect_reports_equal(const DensifyReport& got, const DensifyReport& want) {
  EXPECT_EQ(got.to_string(), want.to_string());
  EXPECT_EQ(got.after, got.before + got.cloned + got.split - got.pruned());
}

// One Gaussian at the origin, identity rotation, every scale `scale`, opacity 0.5, nonzero moments.
TrainingState one_gaussian(float scale, float grad_accum, uint32_t denom) {
  GaussianModel m;
  m.channels = 1;
  m.sh_degree = 1;
  m.resize(1);
  for (int a = 0; a < 3; ++a) m.means[a] = 0.1f * static_cast<float>(a + 1);
  for (int a = 0; a < 3; ++a) m.log_scales[a] = std::log(scale) - 0.1f * static_cast<float>(a);
  m.quats = {0.9f, 0.1f, 0.2f, -0.3f};
  m.opacity_logits = {0.0f};
  m.sh = {0.5f, 0.1f, -0.1f, 0.2f};
  TrainingState s = TrainingState::fresh(m);
  for (uint32_t g = 0; g < kParamGroupCount; ++g) {
    for (auto& x : s.exp_avg[g]) x = 0.25f;
    for (auto& x : s.exp_avg_sq[g]) x = 0.5f;
  }
  s.grad_accum = {grad_accum};
  s.denom = {denom};
  s.max_radius = {5.0f};
  return s;
}

TrainingState concat(const std::vector<TrainingState>& parts) {
  TrainingState out = parts[0];
  for (size_t k = 1; k < parts.size(); ++k) {
    const TrainingState& p = parts[k];
    for (uint32_t g = 0; g < kParamGroupCount; ++g) {
      auto& v = group_values(out.model, g);
      const auto& w = group_values(p.model, g);
      v.insert(v.end(), w.begin(), w.end());
      out.exp_avg[g].insert(out.exp_avg[g].end(), p.exp_avg[g].begin(), p.exp_avg[g].end());
      out.exp_avg_sq[g].insert(out.exp_avg_sq[g].end(), p.exp_avg_sq[g].begin(), p.exp_avg_sq[g].end());
    }
    out.grad_accum.insert(out.grad_accum.end(), p.grad_accum.begin(), p.grad_accum.end());
    out.denom.insert(out.denom.end(), p.denom.begin(), p.denom.end());
    out.max_radius.insert(out.max_radius.end(), p.max_radius.begin(), p.max_radius.end());
  }
  return out;
}

// A random state: mixed scales (clone, split, too large), gradients around the threshold, radii around the
// screen limit, some transparent and some non-finite rows, random moments.
TrainingState random_state(size_t n, uint32_t seed) {
  GaussianModel m = testing::random_scene(n, 1, 2, seed);
  std::mt19937 rng(seed + 1);
  std::uniform_real_distribution<float> u(0.0f, 1.0f);
  TrainingState s = TrainingState::fresh(m);
  for (size_t i = 0; i < n; ++i) {
    const float r = u(rng);
    const float base = r < 0.4f ? std::log(0.004f) : (r < 0.8f ? std::log(0.04f) : std::log(0.14f));
    for (int a = 0; a < 3; ++a) s.model.log_scales[3 * i + a] = base - 0.5f * u(rng);
    if (u(rng) < 0.1f) s.model.opacity_logits[i] = -6.0f;
    s.denom[i] = static_cast<uint32_t>(u(rng) * 4.0f);
    s.grad_accum[i] = 4e-4f * u(rng) * static_cast<float>(s.denom[i]);
    s.max_radius[i] = 30.0f * u(rng);
  }
  for (uint32_t g = 0; g < kParamGroupCount; ++g) {
    for (auto& x : s.exp_avg[g]) x = u(rng) - 0.5f;
    for (auto& x : s.exp_avg_sq[g]) x = u(rng);
  }
  if (n > 10) {
    s.model.means[3 * 3 + 1] = std::numeric_limits<float>::quiet_NaN();
    s.model.sh[7 * m.sh_coeffs() + 2] = std::numeric_limits<float>::infinity();
    s.model.quats[4 * 9] = -std::numeric_limits<float>::infinity();
  }
  return s;
}

struct Result {
  TrainingState state;
  DensifyReport report;
};

Result run_device(engine::Context& ctx, const TrainingState& in, const DensifyOptions& o, uint32_t step,
                  const std::vector<float>* plane = nullptr) {
  TrainableGaussians t(ctx, in);
  std::unique_ptr<DeviceArray<float>> d_plane;
  if (plane) {
    d_plane = std::make_unique<DeviceArray<float>>(ctx, "plane distances", plane->size());
    d_plane->upload(*plane);
  }
  Result r;
  r.report = t.densify_and_prune(o, kExtent, step, plane ? &d_plane->buffer() : nullptr);
  r.state = t.download_state();
  EXPECT_EQ(t.size(), r.report.after);
  EXPECT_GE(t.capacity(), t.size());
  return r;
}

Result run_reference(const TrainingState& in, const DensifyOptions& o, uint32_t step,
                     const std::vector<float>* plane = nullptr) {
  const uint32_t sv = in.model.sh_coeffs() * in.model.channels;
  const DensifyParams p =
      make_densify_params(o, kExtent, step, static_cast<uint32_t>(in.size()), sv, plane != nullptr);
  Result r;
  r.state = densify_reference(in, p, o.reset_stats, plane ? *plane : std::vector<float>{}, &r.report);
  return r;
}

TEST_F(DensifyTest, HighGradientSmallGaussianIsClonedExactlyWithZeroMoments) {
  const TrainingState in =
      concat({one_gaussian(0.05f, 0.0f, 1), one_gaussian(0.005f, 1e-3f, 2), one_gaussian(0.005f, 1e-4f, 1)});
  DensifyOptions o;
  const Result got = run_device(context(), in, o, 500);
  EXPECT_EQ(got.report.cloned, 1u);
  EXPECT_EQ(got.report.split, 0u);
  EXPECT_EQ(got.report.pruned(), 0u);
  ASSERT_EQ(got.state.size(), 4u);
  // Rows: 0 (kept), 1 (the original), 1's clone, 2 (kept, below the threshold).
  const size_t source[] = {0, 1, 1, 2};
  for (uint32_t g = 0; g < kParamGroupCount; ++g) {
    const size_t w = group_values(in.model, g).size() / 3;
    for (size_t row = 0; row < 4; ++row)
      for (size_t k = 0; k < w; ++k) {
        ASSERT_EQ(bits(group_values(got.state.model, g)[row * w + k]),
                  bits(group_values(in.model, g)[source[row] * w + k]));
        const float m = row == 2 ? 0.0f : 0.25f, v = row == 2 ? 0.0f : 0.5f;
        ASSERT_EQ(got.state.exp_avg[g][row * w + k], m) << row;
        ASSERT_EQ(got.state.exp_avg_sq[g][row * w + k], v) << row;
      }
  }
  for (size_t row = 0; row < 4; ++row) EXPECT_EQ(got.state.denom[row], 0u);  // 3DGS resets statistics
  const Result want = run_reference(in, o, 500);
  expect_states_match(got.state, want.state);
  expect_reports_equal(got.report, want.report);
}

TEST_F(DensifyTest, HighGradientLargeGaussianIsSplitIntoTwoChildrenWithinThreeSigma) {
  const TrainingState in = concat({one_gaussian(0.005f, 0.0f, 1), one_gaussian(0.05f, 5e-4f, 1)});
  DensifyOptions o;
  const Result got = run_device(context(), in, o, 600);
  EXPECT_EQ(got.report.split, 1u);
  EXPECT_EQ(got.report.cloned, 0u);
  ASSERT_EQ(got.state.size(), 3u);
  const float log_div = static_cast<float>(std::log(1.6));
  using namespace splat_math;
  const dvec4 q(0.9, 0.1, 0.2, -0.3);
  const dmat3 R = rotation_from_unit_quat(unit_quat(q));
  for (size_t row = 1; row <= 2; ++row) {
    dvec3 d;
    for (int a = 0; a < 3; ++a) {
      // Scales / 1.6 in log space (float subtraction, as the kernel).
      EXPECT_NEAR(got.state.model.log_scales[3 * row + a], in.model.log_scales[3 + a] - log_div, 1e-6);
      d[a] = double{got.state.model.means[3 * row + a]} - in.model.means[3 + a];
    }
    const dvec3 local = transpose(R) * d;  // in the parent's principal axes
    for (int a = 0; a < 3; ++a) {
      const double sigma = std::exp(double{in.model.log_scales[3 + a]});
      EXPECT_LE(std::abs(local[a]), 3.0 * sigma * (1 + 1e-5)) << "child " << row << " axis " << a;
    }
    EXPECT_GT(length(d), 0.0);
    for (uint32_t g = 0; g < kParamGroupCount; ++g) {
      const size_t w = group_values(in.model, g).size() / 2;
      for (size_t k = 0; k < w; ++k) ASSERT_EQ(got.state.exp_avg[g][row * w + k], 0.0f);
    }
    EXPECT_EQ(got.state.model.opacity_logits[row], in.model.opacity_logits[1]);
  }
  EXPECT_NE(got.state.model.means[3], got.state.model.means[6]);  // two different samples
  const Result want = run_reference(in, o, 600);
  expect_states_match(got.state, want.state);
  expect_reports_equal(got.report, want.report);
}

TEST_F(DensifyTest, PrunesByEachReasonAndKeepsSurvivorOrder) {
  std::vector<TrainingState> parts;
  for (int i = 0; i < 9; ++i) parts.push_back(one_gaussian(0.005f, 0.0f, 1));
  parts[1].model.opacity_logits[0] = std::log(0.004f / 0.996f);               // transparent
  parts[2].model.sh[3] = std::numeric_limits<float>::quiet_NaN();             // non-finite SH
  parts[3].model.means[0] = std::numeric_limits<float>::infinity();           // non-finite mean
  for (int a = 0; a < 3; ++a) parts[4].model.log_scales[a] = std::log(0.2f);  // larger than 0.1 extent
  parts[5].max_radius[0] = 25.0f;                                             // larger than 20 px on screen
  parts[7].model.opacity_logits[0] = std::numeric_limits<float>::quiet_NaN();
  TrainingState in = concat(parts);
  for (size_t i = 0; i < in.size(); ++i) in.model.means[3 * i + 2] = static_cast<float>(i);
  std::vector<float> plane(in.size(), 0.01f);
  plane[6] = 0.5f;                                     // beyond the plane bound
  plane[8] = std::numeric_limits<float>::quiet_NaN();  // no plane: kept
  DensifyOptions o;
  o.max_plane_distance_m = 0.1f;
  // Before the first opacity reset: no size prunes.
  const Result early = run_device(context(), in, o, 100, &plane);
  EXPECT_EQ(early.report.pruned_opacity, 1u);
  EXPECT_EQ(early.report.pruned_nonfinite, 3u);
  EXPECT_EQ(early.report.pruned_plane, 1u);
  EXPECT_EQ(early.report.pruned_world_size + early.report.pruned_screen_size, 0u);
  EXPECT_EQ(early.state.size(), 4u);
  // After it: size prunes too.
  const Result late = run_device(context(), in, o, 3001, &plane);
  EXPECT_EQ(late.report.pruned_world_size, 1u);
  EXPECT_EQ(late.report.pruned_screen_size, 1u);
  ASSERT_EQ(late.state.size(), 2u);
  EXPECT_EQ(late.state.model.means[2], 0.0f);  // survivors 0 and 8, in order
  EXPECT_EQ(late.state.model.means[5], 8.0f);
  expect_states_match(late.state, run_reference(in, o, 3001, &plane).state);
  expect_reports_equal(late.report, run_reference(in, o, 3001, &plane).report);
}

TEST_F(DensifyTest, MatchesReferenceAtEverySize) {
  for (size_t n : {size_t{0}, size_t{1}, size_t{255}, size_t{256}, size_t{257}, size_t{100000}}) {
    SCOPED_TRACE(n);
    const TrainingState in = random_state(n, static_cast<uint32_t>(n) + 3);
    DensifyOptions o;
    o.seed = 42;
    const uint32_t step = n % 2 ? 3500 : 700;
    const Result got = run_device(context(), in, o, step);
    const Result want = run_reference(in, o, step);
    expect_reports_equal(got.report, want.report);
    expect_states_match(got.state, want.state);
    if (n >= 255) {
      EXPECT_GT(got.report.cloned, 0u);
      EXPECT_GT(got.report.split, 0u);
      EXPECT_GT(got.report.pruned(), 0u);
    }
  }
}

TEST_F(DensifyTest, KeepsStatisticsWhenAskedAndPrunesByPlaneDistance) {
  const TrainingState in = random_state(1000, 9);
  std::vector<float> plane(in.size());
  std::mt19937 rng(2);
  std::uniform_real_distribution<float> u(0.0f, 0.2f);
  for (auto& d : plane) d = u(rng);
  DensifyOptions o;
  o.reset_stats = false;
  o.max_plane_distance_m = 0.15f;
  const Result got = run_device(context(), in, o, 4000, &plane);
  const Result want = run_reference(in, o, 4000, &plane);
  EXPECT_GT(got.report.pruned_plane, 0u);
  expect_reports_equal(got.report, want.report);
  expect_states_match(got.state, want.state);
}

TEST_F(DensifyTest, MaxGaussiansCapsTheTotal) {
  const TrainingState in = random_state(5000, 4);
  DensifyOptions o;
  o.max_gaussians = 5100;  // far fewer than the candidates
  const Result got = run_device(context(), in, o, 200);
  EXPECT_LE(got.state.size(), 5100u);
  EXPECT_EQ(got.report.cloned + got.report.split, 100u);
  EXPECT_GT(got.report.capped, 0u);
  const Result want = run_reference(in, o, 200);
  expect_reports_equal(got.report, want.report);
  expect_states_match(got.state, want.state);
  // At the cap already: nothing densifies.
  o.max_gaussians = 4000;
  const Result full = run_device(context(), in, o, 200);
  EXPECT_EQ(full.report.cloned + full.report.split, 0u);
  EXPECT_LE(full.state.size(), in.size());
}

TEST_F(DensifyTest, DeterministicForASeed) {
  const TrainingState in = random_state(3000, 8);
  DensifyOptions o;
  o.seed = 7;
  const Result a = run_device(context(), in, o, 900);
  const Result b = run_device(context(), in, o, 900);
  ASSERT_EQ(a.state.size(), b.state.size());
  for (size_t j = 0; j < a.state.model.means.size(); ++j)
    ASSERT_EQ(bits(a.state.model.means[j]), bits(b.state.model.means[j])) << j;
  o.seed = 8;
  const Result c = run_device(context(), in, o, 900);
  ASSERT_EQ(a.state.size(), c.state.size());
  EXPECT_NE(a.state.model.means, c.state.model.means);
}

TEST_F(DensifyTest, RepeatedDensificationGrowsCapacityAndStaysConsistent) {
  const TrainingState in = random_state(2000, 12);
  TrainableGaussians t(context(), in);
  DensifyOptions o;
  TrainingState want = in;
  size_t capacity = t.capacity();
  for (uint32_t round = 0; round < 4; ++round) {
    // A gradient above the threshold for every third Gaussian, on the device and in the reference.
    TrainingState s = t.download_state();
    for (size_t i = 0; i < s.size(); ++i) {
      s.denom[i] = want.denom[i] = 1;
      s.grad_accum[i] = want.grad_accum[i] = (i % 3 == 0) ? 1e-3f : 0.0f;
    }
    t.load_state(s);
    const DensifyReport r = t.densify_and_prune(o, kExtent, 100 + round);
    const uint32_t sv = want.model.sh_coeffs() * want.model.channels;
    DensifyReport rr;
    want = densify_reference(
        want, make_densify_params(o, kExtent, 100 + round, uint32_t(want.size()), sv, false), true, {}, &rr);
    expect_reports_equal(r, rr);
    expect_states_match(t.download_state(), want);
    EXPECT_GE(t.capacity(), t.size());
    capacity = std::max(capacity, t.capacity());
  }
  EXPECT_GT(t.size(), in.size());
  EXPECT_GT(capacity, in.size());
}

TEST_F(DensifyTest, ResetOpacityClampsAndZeroesOpacityMoments) {
  TrainingState in = random_state(300, 5);
  in.model.opacity_logits[4] = std::numeric_limits<float>::quiet_NaN();
  TrainableGaussians t(context(), in);
  engine::Sequence s(context());
  t.record_reset_opacity(s, 0.01f);
  s.submit_and_wait();
  const TrainingState got = t.download_state();
  const float max_logit = static_cast<float>(std::log(0.01 / 0.99));
  for (size_t i = 0; i < in.size(); ++i) {
    if (i == 4) {
      EXPECT_TRUE(std::isnan(got.model.opacity_logits[i]));
    } else {
      EXPECT_EQ(got.model.opacity_logits[i], std::min(in.model.opacity_logits[i], max_logit)) << i;
    }
    EXPECT_EQ(got.exp_avg[kOpacityLogits][i], 0.0f);
    EXPECT_EQ(got.exp_avg_sq[kOpacityLogits][i], 0.0f);
    EXPECT_EQ(bits(got.exp_avg[kMeans][3 * i]), bits(in.exp_avg[kMeans][3 * i]));  // other groups untouched
  }
}

// Statistics after two backwards against the rasterizer's downloaded gradients and the reference projection.
TEST_F(DensifyTest, AccumulatesScreenGradientVisibilityAndRadius) {
  const GaussianModel model = testing::random_scene(400, 1, 1, 21);
  SplatCamera camera = testing::camera_looking_down_z(96, 80);
  camera.sh_degree = 1;
  TrainableGaussians t(context(), model);
  Rasterizer raster(context(), 1);
  std::vector<double> accum(model.size(), 0.0);
  std::vector<uint32_t> denom(model.size(), 0);
  for (int pass = 0; pass < 2; ++pass) {
    raster.forward(t.gaussians(), camera);
    const auto up = raster.upstream_buffers();
    std::mt19937 rng(pass);
    std::normal_distribution<float> normal(0.0f, 1.0f);
    std::vector<float> gi(96 * 80);
    for (auto& x : gi) x = normal(rng);
    const_cast<engine::Buffer*>(up.image)->upload(gi.data(), gi.size() * 4);
    engine::Sequence s(context());
    s.fill(*up.depth, 0u, 96 * 80 * 4);
    s.fill(*up.alpha, 0u, 96 * 80 * 4);
    const Rasterizer::DeviceGrads grads = raster.record_backward(s);
    t.record_accumulate_stats(s, grads, *raster.device_outputs().rects, camera);
    s.submit_and_wait();
    const GaussianGrads<float> g = raster.download_grads();
    std::vector<uint32_t> rects(2 * model.size());  // packed: x0 | y0 << 16, x1 | y1 << 16
    raster.device_outputs().rects->download(rects.data(), rects.size() * 4);
    for (size_t i = 0; i < model.size(); ++i) {
      const uint32_t x0 = rects[2 * i] & 0xffffu, y0 = rects[2 * i] >> 16, x1 = rects[2 * i + 1] & 0xffffu,
                     y1 = rects[2 * i + 1] >> 16;
      if (x1 <= x0 || y1 <= y0) continue;
      accum[i] += std::hypot(g.means2d[2 * i] * 48.0, g.means2d[2 * i + 1] * 40.0);
      ++denom[i];
    }
  }
  const TrainingState st = t.download_state();
  size_t visible = 0;
  for (size_t i = 0; i < model.size(); ++i) {
    ASSERT_EQ(st.denom[i], denom[i]) << i;
    ASSERT_NEAR(st.grad_accum[i], accum[i], 1e-5 * accum[i] + 1e-12) << i;
    if (denom[i] == 0) {
      EXPECT_EQ(st.max_radius[i], 0.0f);
      continue;
    }
    ++visible;
    using namespace splat_math;
    ViewGeometry v{
        camera.R_cam_world,   camera.t_cam_world,   camera.fx, camera.fy, camera.cx, camera.cy, camera.near_m,
        double(camera.width), double(camera.height)};
    const Projected p = project_gaussian(
        v, dvec3(model.means[3 * i], model.means[3 * i + 1], model.means[3 * i + 2]),
        dvec3(model.log_scales[3 * i], model.log_scales[3 * i + 1], model.log_scales[3 * i + 2]),
        dvec4(model.quats[4 * i], model.quats[4 * i + 1], model.quats[4 * i + 2], model.quats[4 * i + 3]),
        model.opacity_logits[i]);
    const double radius = std::max(p.extent.x, p.extent.y);
    ASSERT_NEAR(st.max_radius[i], radius, 1e-3 * radius + 1e-4) << i;
  }
  EXPECT_GT(visible, model.size() / 2);
}

}  // namespace
}  // namespace litgs::kernels
