// Forward parity on real geometry: Gaussians on the 138,766 structure-from-motion points of the Mip-NeRF 360
// garden scene (gsplat's test data), seen from its 3 cameras at 648x420.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <random>

#include "gpu_test.h"
#include "kernels/splat/rasterizer.h"
#include "kernels/splat/reference.h"
#include "npz_reader.h"
#include "splat_scenes.h"
#include "tests/support/test_data.h"

namespace litgs {
namespace {

// Throws (the test fails, naming the path) when the archive is missing: never a silent skip.
std::string garden_path() {
  return testing::test_data("gsplat-garden/test_garden.npz").string();
}

struct Garden {
  kernels::GaussianModel model;
  std::vector<kernels::SplatCamera> cameras;
};

// Isotropic Gaussians sized by the median nearest-neighbour spacing of a sample of points (as 3DGS sizes
// its initial Gaussians by neighbour distance), coloured from the points, opacity 0.7.
Garden load_garden(uint32_t channels, uint32_t degree) {
  const std::string path = garden_path();
  const auto means = testing::read_npz_array(path, "means3d").as_float();
  const auto colors = testing::read_npz_array(path, "colors").as_float();
  const auto viewmats = testing::read_npz_array(path, "viewmats").as_float();
  const auto Ks = testing::read_npz_array(path, "Ks").as_float();
  const auto width = testing::read_npz_array(path, "width").as_scalar_int();
  const auto height = testing::read_npz_array(path, "height").as_scalar_int();
  const size_t n = means.size() / 3;

  std::mt19937 rng(1);
  std::vector<double> spacing;
  for (int s = 0; s < 200; ++s) {
    const size_t i = rng() % n;
    double best = 1e30;
    for (size_t j = 0; j < n; ++j) {
      if (j == i) continue;
      const double dx = means[3 * i] - means[3 * j], dy = means[3 * i + 1] - means[3 * j + 1],
                   dz = means[3 * i + 2] - means[3 * j + 2];
      best = std::min(best, dx * dx + dy * dy + dz * dz);
    }
    spacing.push_back(std::sqrt(best));
  }
  std::nth_element(spacing.begin(), spacing.begin() + 100, spacing.end());
  const float log_scale = static_cast<float>(std::log(std::max(spacing[100], 1e-4)));

  Garden g;
  g.model.channels = channels;
  g.model.sh_degree = degree;
  g.model.resize(n);
  std::uniform_real_distribution<float> u(-0.05f, 0.05f);
  const uint32_t K = g.model.sh_coeffs();
  for (size_t i = 0; i < n; ++i) {
    for (int a = 0; a < 3; ++a) {
      g.model.means[3 * i + a] = means[3 * i + a];
      g.model.log_scales[3 * i + a] = log_scale;
    }
    g.model.quats[4 * i] = 1.0f;
    g.model.opacity_logits[i] = 0.85f;
    for (uint32_t c = 0; c < channels; ++c) {
      const float value = channels == 3 ? colors[3 * i + c] / 255.0f
                                        : (colors[3 * i] + colors[3 * i + 1] + colors[3 * i + 2]) / 765.0f;
      g.model.sh[i * K * channels + c] = (value - 0.5f) / 0.28209479f;
      for (uint32_t k = 1; k < K; ++k) g.model.sh[(i * K + k) * channels + c] = u(rng);
    }
  }
  for (int v = 0; v < 3; ++v) {
    kernels::SplatCamera c;
    for (int row = 0; row < 3; ++row) {
      for (int col = 0; col < 3; ++col) c.R_cam_world[col][row] = viewmats[v * 16 + row * 4 + col];
      c.t_cam_world[row] = viewmats[v * 16 + row * 4 + 3];
    }
    c.fx = Ks[v * 9 + 0];
    c.cx = Ks[v * 9 + 2];
    c.fy = Ks[v * 9 + 4];
    c.cy = Ks[v * 9 + 5];
    c.width = static_cast<uint32_t>(width);
    c.height = static_cast<uint32_t>(height);
    c.sh_degree = degree;
    g.cameras.push_back(c);
  }
  return g;
}

class RasterizerGarden : public testing::GpuTest {
 protected:
  void check_parity(uint32_t channels, uint32_t degree) {
    const Garden garden = load_garden(channels, degree);
    kernels::DeviceGaussians g(context(), garden.model);
    kernels::Rasterizer r(context(), channels);
    for (size_t v = 0; v < garden.cameras.size(); ++v) {
      r.forward(g, garden.cameras[v]);
      const auto got = r.download_images();
      const auto want = kernels::reference_forward(garden.model, garden.cameras[v]);
      EXPECT_EQ(got.intersections, want.intersections) << "view " << v;
      EXPECT_GT(got.intersections, 100000u) << "the view sees the scene";
      const auto img = testing::compare(got.image, want.image, 1e-4);
      const auto alp = testing::compare(got.alpha, want.alpha, 1e-4);
      const auto dep = testing::compare(got.depth, want.depth, 1e-3);
      const auto outside = [](const testing::Agreement& a) {
        return static_cast<unsigned long long>(
            std::llround((1.0 - a.fraction_within) * static_cast<double>(a.count)));
      };
      std::printf(
          "garden C=%u view %zu: %llu intersections; image max|d| %.2e, %llu of %zu values off by > 1e-4; "
          "alpha %.2e, %llu of %zu; depth %.2e, %llu of %zu off by > 1e-3\n",
          channels, v, static_cast<unsigned long long>(got.intersections), img.max_abs, outside(img),
          img.count, alp.max_abs, outside(alp), alp.count, dep.max_abs, outside(dep), dep.count);
      // float32 against double over lists of thousands of Gaussians: a few pixels cross the 1/255 or
      // T = 1e-4 thresholds at a different entry; everything else agrees to 1e-4. Measured on lavapipe: at
      // most 38 of 816,480 image values (99.995%), 7 of 272,160 alpha values and 1 depth value outside, the
      // worst off by 3.9e-3. The README states the figures asserted here: 99.99% within, none off by 5e-3.
      EXPECT_GE(img.fraction_within, 0.9999) << "view " << v;
      EXPECT_GE(alp.fraction_within, 0.9999) << "view " << v;
      EXPECT_GE(dep.fraction_within, 0.9999) << "view " << v;
      EXPECT_LT(img.max_abs, 5e-3) << "view " << v;
      EXPECT_LT(alp.max_abs, 5e-3) << "view " << v;
      EXPECT_LT(dep.max_abs, 5e-3) << "view " << v << " (metres)";
    }
  }
};

TEST_F(RasterizerGarden, RgbDegree0MatchesReference) {
  check_parity(3, 0);
}
TEST_F(RasterizerGarden, ThermalDegree3MatchesReference) {
  check_parity(1, 3);
}

}  // namespace
}  // namespace litgs
