// Tile lists far longer than one rasterize pass: the rasterizer walks them in passes that carry each pixel's
// blend state (kernels/splat/splat_shared.h). lavapipe ends an invocation's loops silently after 65535
// iterations, so before the passes a 60,000-entry list was cut short without an error. Here one 16x16 tile is
// covered by 100k and by 1M Gaussians, faint enough that no pixel saturates, so every entry of the list
// changes the result: forward and all three backward modes against the double-precision reference.
#include <gtest/gtest.h>

#include <cmath>
#include <cstring>
#include <random>
#include <string>

#include "gpu_test.h"
#include "kernels/splat/rasterizer.h"
#include "kernels/splat/reference.h"
#include "splat_compare.h"
#include "splat_scenes.h"

namespace litgs {
namespace {

using kernels::DeviceGaussians;
using kernels::GaussianModel;
using kernels::Rasterizer;
using kernels::RasterizerOptions;
using kernels::SplatCamera;

constexpr uint32_t kTile = 16;

// A 16x16 image (one tile) seen by a camera at the origin looking down +z.
SplatCamera one_tile_camera() {
  SplatCamera c;
  c.width = c.height = kTile;
  c.fx = c.fy = 16.0;
  c.cx = c.cy = 8.0;
  c.sh_degree = 0;
  return c;
}

// n point-like Gaussians (the 0.3 px^2 low-pass sets their footprint) at depths 2-10 m over the tile,
// opacity 0.0045: each reaches only pixel centres within 0.29 px with alpha >= 1/255, so a pixel is hit by
// about n / 750 of them and keeps a transmittance well above the 1e-4 stop (1M: T ~ 0.004). Every entry lies
// in the tile's list, and the hits are spread over the whole depth order: a walk cut anywhere changes pixels.
GaussianModel faint_points_on_one_tile(size_t n, uint32_t seed) {
  GaussianModel m;
  m.channels = 1;
  m.sh_degree = 0;
  m.resize(n);
  const SplatCamera cam = one_tile_camera();
  std::mt19937 rng(seed);
  // Centres at least 0.3 px inside the tile, so that no footprint (0.29 px) reaches a neighbouring tile.
  std::uniform_real_distribution<double> pixel(0.3, kTile - 0.3), depth(2.0, 10.0), unit(0.0, 1.0);
  const float logit = static_cast<float>(std::log(0.0045 / (1.0 - 0.0045)));
  for (size_t i = 0; i < n; ++i) {
    const double z = depth(rng);
    m.means[3 * i] = static_cast<float>((pixel(rng) - cam.cx) * z / cam.fx);
    m.means[3 * i + 1] = static_cast<float>((pixel(rng) - cam.cy) * z / cam.fy);
    m.means[3 * i + 2] = static_cast<float>(z);
    // Millimetre-sized and anisotropic, randomly turned: every parameter has a gradient (an isotropic
    // Gaussian's rotation gradient is exactly zero, and its float value pure rounding).
    for (int a = 0; a < 3; ++a)
      m.log_scales[3 * i + a] = static_cast<float>(std::log(1e-3 * (0.5 + 2.5 * unit(rng))));
    for (int a = 0; a < 4; ++a) m.quats[4 * i + a] = static_cast<float>(unit(rng) - 0.5);
    m.opacity_logits[i] = logit;
    m.sh[i] = static_cast<float>(unit(rng) - 0.5);  // colour 0.5 + 0.28 * sh in 0.36..0.64
  }
  return m;
}

void expect_images_match(const kernels::RenderImages<float>& got, const kernels::RenderImages<double>& want) {
  ASSERT_EQ(got.image.size(), want.image.size());
  double worst_image = 0, worst_alpha = 0, worst_depth = 0;
  for (size_t p = 0; p < got.image.size(); ++p) {
    worst_image = std::max(worst_image, std::abs(got.image[p] - want.image[p]));
    worst_alpha = std::max(worst_alpha, std::abs(got.alpha[p] - want.alpha[p]));
    worst_depth = std::max(worst_depth, std::abs(got.depth[p] - want.depth[p]));
    EXPECT_EQ(got.last[p], want.last[p]) << "pixel " << p << ": entries walked";
  }
  // About a thousand float blends per pixel: a few 1e-5 of accumulated rounding.
  EXPECT_LT(worst_image, 2e-4);
  EXPECT_LT(worst_alpha, 2e-4);
  EXPECT_LT(worst_depth, 2e-3);  // metres, at 2-10 m
  std::printf("  image max|d| %.2e, alpha %.2e, depth %.2e m\n", worst_image, worst_alpha, worst_depth);
}

// The most loop iterations per entry: n faint points on the line between pixel rows 7 and 8, within the
// left half of the tile. Each one's 1/255 footprint (0.29 px) reaches no pixel centre (0.5 px away), but the
// footprint test's half-pixel margin makes every entry relevant to the subgroups of those rows: they run
// the per-entry loop for every entry of every chunk. Behind them, one broad Gaussian that every pixel sees,
// so that the backward walks the whole list too.
GaussianModel relevant_but_invisible_points(size_t n, uint32_t seed) {
  GaussianModel m = faint_points_on_one_tile(n + 1, seed);
  const SplatCamera cam = one_tile_camera();
  std::mt19937 rng(seed);
  std::uniform_real_distribution<double> u(0.3, 8.2), depth(2.0, 9.0);
  for (size_t i = 0; i < n; ++i) {
    const double z = depth(rng);
    m.means[3 * i] = static_cast<float>((u(rng) - cam.cx) * z / cam.fx);
    m.means[3 * i + 1] = static_cast<float>((8.0 - cam.cy) * z / cam.fy);
    m.means[3 * i + 2] = static_cast<float>(z);
    for (int a = 0; a < 3; ++a) m.log_scales[3 * i + a] = std::log(1e-4f);
    for (int a = 0; a < 4; ++a) m.quats[4 * i + a] = a == 0 ? 1.0f : 0.0f;
  }
  m.means[3 * n] = 0.0f;  // the broad one, at 9.5 m: behind every point
  m.means[3 * n + 1] = 0.0f;
  m.means[3 * n + 2] = 9.5f;
  const float broad_log_scales[3] = {std::log(2.0f), std::log(1.0f), std::log(0.5f)};
  const float broad_quat[4] = {0.9f, 0.2f, -0.3f, 0.1f};
  for (int a = 0; a < 3; ++a) m.log_scales[3 * n + a] = broad_log_scales[a];
  for (int a = 0; a < 4; ++a) m.quats[4 * n + a] = broad_quat[a];
  m.opacity_logits[n] = 0.0f;
  return m;
}

class RasterizerLongLists : public testing::GpuTest {
 protected:
  // The forward and every backward mode on one tile covered by `n` Gaussians, against the reference.
  void check_one_tile(size_t n) { check_one_tile(faint_points_on_one_tile(n, 7), n, true); }

  void check_one_tile(const GaussianModel& model, size_t n, bool every_pixel_walks_far) {
    const SplatCamera cam = one_tile_camera();
    const kernels::RenderImages<double> want = kernels::reference_forward(model, cam);
    // The scene does what it is meant to: every entry in one list, no pixel saturated, ~n/750 hits each.
    ASSERT_EQ(want.intersections, n);
    double min_T = 1.0;
    for (double a : want.alpha) min_T = std::min(min_T, 1.0 - a);
    EXPECT_GT(min_T, 1e-3) << "a pixel saturated: the tail of the list would not matter";
    uint32_t min_last = UINT32_MAX;
    for (uint32_t l : want.last) min_last = std::min(min_last, l);
    if (every_pixel_walks_far) {
      EXPECT_GT(min_last, n / 2) << "every pixel's walk should reach past the middle of the list";
    }

    const kernels::RenderGradInput grad = testing::random_grad(1, kTile, kTile, 3);
    const kernels::GaussianGrads<double> want_grads = kernels::reference_backward(model, cam, grad, true);
    DeviceGaussians g(context(), model);
    RasterizerOptions atomics, cas, deterministic;
    cas.force_cas_atomics = true;
    deterministic.deterministic = true;
    for (const auto& [name, options] : {std::pair{"float atomics", atomics}, std::pair{"CAS", cas},
                                        std::pair{"deterministic", deterministic}}) {
      SCOPED_TRACE(name);
      Rasterizer r(context(), 1, options);
      r.forward(g, cam);
      const kernels::RenderImages<float> got = r.download_images();
      EXPECT_EQ(got.intersections, n);
      EXPECT_EQ(got.walks_cut_short, 0u);
      expect_images_match(got, want);
      r.backward(grad);
      testing::expect_grads_match(r.download_grads(), want_grads);
      const kernels::RasterizerCounters c = r.read_counters();
      EXPECT_EQ(c.longest_tile_list, n);
      EXPECT_EQ(c.walks_cut_short, 0u) << "a pass exceeded the driver's loop limit";
      EXPECT_GT(c.forward_passes, 1u) << "the list should need several forward passes";
      EXPECT_GT(c.backward_passes, 1u) << "the list should need several backward passes";
      std::printf("  %s: %zu entries, %u forward passes of %u, %u backward passes of %u\n", name, n,
                  c.forward_passes, r.forward_entries_per_pass(), c.backward_passes,
                  r.backward_entries_per_pass());
    }
  }
};

TEST_F(RasterizerLongLists, OneTileCoveredBy100kGaussians) {
  check_one_tile(100'000);
}

TEST_F(RasterizerLongLists, OneTileCoveredBy1MGaussians) {
  check_one_tile(1'000'000);
}

// The loop-cost bound's worst case (every entry relevant to a subgroup) stays within the driver's limit.
TEST_F(RasterizerLongLists, EveryEntryRelevantToASubgroupStaysWithinTheLoopLimit) {
  const size_t n = 60'000;
  const GaussianModel model = relevant_but_invisible_points(n, 9);
  const auto want = kernels::reference_forward(model, one_tile_camera());
  EXPECT_EQ(want.last[7 * kTile], n + 1) << "row 7 walks the whole list to the broad Gaussian";
  check_one_tile(model, n + 1, false);
}

// Many passes over short lists (37 entries, not a multiple of any subgroup size) give the bits of one pass:
// the carried state is exact. Random scene with several tiles, lists of a few hundred entries.
TEST_F(RasterizerLongLists, ManyShortPassesEqualOnePassBitForBit) {
  const GaussianModel model = testing::random_scene(3000, 3, 3, 11);
  const SplatCamera cam = testing::camera_looking_down_z(61, 47);
  const kernels::RenderGradInput grad = testing::random_grad(3, cam.width, cam.height, 4);
  DeviceGaussians g(context(), model);
  RasterizerOptions one, many;
  one.deterministic = many.deterministic = true;
  one.entries_per_pass = 1u << 30;
  many.entries_per_pass = 37;
  Rasterizer r1(context(), 3, one), r2(context(), 3, many);
  r1.forward(g, cam);
  r2.forward(g, cam);
  const auto a = r1.download_images(), b = r2.download_images();
  ASSERT_GT(r2.read_counters().forward_passes, 5u);
  EXPECT_EQ(r1.read_counters().forward_passes, 1u);
  EXPECT_EQ(0, std::memcmp(a.image.data(), b.image.data(), a.image.size() * sizeof(float)));
  EXPECT_EQ(0, std::memcmp(a.depth.data(), b.depth.data(), a.depth.size() * sizeof(float)));
  EXPECT_EQ(0, std::memcmp(a.alpha.data(), b.alpha.data(), a.alpha.size() * sizeof(float)));
  EXPECT_EQ(a.last, b.last);
  r1.backward(grad);
  r2.backward(grad);
  const auto ga = r1.download_grads(), gb = r2.download_grads();
  EXPECT_EQ(ga.means, gb.means);
  EXPECT_EQ(ga.log_scales, gb.log_scales);
  EXPECT_EQ(ga.quats, gb.quats);
  EXPECT_EQ(ga.opacity_logits, gb.opacity_logits);
  EXPECT_EQ(ga.sh, gb.sh);
  EXPECT_EQ(ga.means2d, gb.means2d);
}

// The cut-walk counter sees a pass that is too long for the driver: with a whole 400k list in one pass,
// lavapipe's loop limit (65,535 iterations of all of an invocation's loops together) ends the walks early:
// each chunk of 8 entries takes at least two iterations (the chunk and one of its entries), so any list above
// ~262k entries is cut, and the render says so. Devices without such a limit walk the whole list and must
// match the reference.
TEST_F(RasterizerLongLists, OversizedPassIsCountedWhereTheDriverCutsIt) {
  const size_t n = 400'000;
  const GaussianModel model = faint_points_on_one_tile(n, 7);
  const SplatCamera cam = one_tile_camera();
  DeviceGaussians g(context(), model);
  RasterizerOptions oversized;
  oversized.entries_per_pass = 1u << 30;
  Rasterizer r(context(), 1, oversized);
  r.forward(g, cam);
  const auto got = r.download_images();
  const bool loop_limited_driver = context().info().name.find("llvmpipe") != std::string::npos;
  if (loop_limited_driver) {
    EXPECT_GT(got.walks_cut_short, 0u) << "lavapipe cut the 400k walk, and the counter must show it";
  } else {
    EXPECT_EQ(got.walks_cut_short, 0u);
    expect_images_match(got, kernels::reference_forward(model, cam));
  }
  std::printf("  %s: %u walks cut short in one pass of %zu entries\n", context().info().name.c_str(),
              got.walks_cut_short, n);
}

// More than 2^32 tile intersections: the exact 64-bit total (the scan of the counts wraps) in the error,
// before any intersection buffer is made. 70,000 Gaussians, each over all 65,536 tiles of a 4096x4096 view.
TEST_F(RasterizerLongLists, MoreThan2To32IntersectionsIsAClearError) {
  const size_t n = 70'000;
  GaussianModel m;
  m.channels = 1;
  m.sh_degree = 0;
  m.resize(n);
  for (size_t i = 0; i < n; ++i) {
    m.means[3 * i + 2] = 10.0f + 1e-4f * static_cast<float>(i);
    for (int a = 0; a < 3; ++a) m.log_scales[3 * i + a] = std::log(100.0f);
    m.quats[4 * i] = 1.0f;
    m.opacity_logits[i] = 2.0f;
  }
  SplatCamera cam;
  cam.width = cam.height = 4096;
  cam.fx = cam.fy = 2048.0;
  cam.cx = cam.cy = 2048.0;
  cam.sh_degree = 0;
  DeviceGaussians g(context(), m);
  Rasterizer r(context(), 1);
  const std::string expected_total = std::to_string(uint64_t{n} * 65536);  // 4,587,520,000
  try {
    r.forward(g, cam);
    FAIL() << "a render of " << expected_total << " intersections must not proceed";
  } catch (const std::length_error& e) {
    EXPECT_NE(std::string(e.what()).find(expected_total + " tile intersections"), std::string::npos)
        << e.what();
  }
}

}  // namespace
}  // namespace litgs
