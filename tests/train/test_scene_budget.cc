// The scene-derived Gaussian budget (host/train/scene_budget.h): the surface the training views see, in
// pixels of the finest view, on scenes whose answer is known by construction.
#include <gtest/gtest.h>

#include <cmath>
#include <limits>
#include <random>

#include "host/train/scene_budget.h"

namespace litgs::host {
namespace {

// A camera at (0, 0, z0) looking along +z (world = camera axes shifted), 640x512, f = 200 px.
kernels::SplatCamera camera_at(double z0) {
  kernels::SplatCamera c;
  c.t_cam_world = glm::dvec3(0, 0, -z0);
  c.fx = c.fy = 200;
  c.cx = 320;
  c.cy = 256;
  c.width = 640;
  c.height = 512;
  return c;
}

// A square of side `side_m` on the plane z = 2, points every `step_m`.
std::vector<Eigen::Vector3d> grid_wall(double side_m, double step_m) {
  std::vector<Eigen::Vector3d> pts;
  const int n = static_cast<int>(std::lround(side_m / step_m));
  for (int i = 0; i < n; ++i)
    for (int j = 0; j < n; ++j)
      pts.emplace_back(-side_m / 2 + (i + 0.5) * step_m, -side_m / 2 + (j + 0.5) * step_m, 2.0);
  return pts;
}

TEST(SceneBudget, AFrontoParallelWallCountsThePixelsItCovers) {
  // 1 m x 1 m at 2 m: 1 cm per pixel, 100 x 100 pixels, 2,500 Gaussians at 4 pixels each.
  const SceneBudget b = derive_scene_budget(grid_wall(1.0, 0.01), {camera_at(0)});
  EXPECT_EQ(b.points_seen, 10000u);
  EXPECT_NEAR(b.median_footprint_m, 0.01, 1e-9);
  EXPECT_NEAR(b.surface_m2, 1.0, 0.1);
  EXPECT_NEAR(b.surface_pixels, 10000, 1000);
  EXPECT_NEAR(b.gaussians, 2500, 250);
}

TEST(SceneBudget, TheFinestViewDecidesAndOverlapIsNotCountedTwice) {
  const std::vector<Eigen::Vector3d> wall = grid_wall(1.0, 0.01);
  const SceneBudget one = derive_scene_budget(wall, {camera_at(0)});
  // The same view twice, and a coarser one (twice as far): nothing changes.
  const SceneBudget same = derive_scene_budget(wall, {camera_at(0), camera_at(0), camera_at(-2)});
  EXPECT_DOUBLE_EQ(same.surface_pixels, one.surface_pixels);
  // A view at half the distance (1 m): each point's footprint halves, its pixels quadruple.
  const SceneBudget closer = derive_scene_budget(wall, {camera_at(0), camera_at(1)});
  EXPECT_NEAR(closer.surface_pixels / one.surface_pixels, 4.0, 1e-6);
}

TEST(SceneBudget, SparseRandomPointsStandForTheSurfaceBetweenThem) {
  std::mt19937 rng(3);
  std::uniform_real_distribution<double> u(-0.5, 0.5);
  std::vector<Eigen::Vector3d> pts;
  for (int i = 0; i < 2000; ++i) pts.emplace_back(u(rng), u(rng), 2.0);
  const SceneBudget b = derive_scene_budget(pts, {camera_at(0)});
  // The k-th-neighbour density estimate is unbiased for random points; the square's border adds a little.
  EXPECT_NEAR(b.surface_m2, 1.0, 0.15);
  EXPECT_NEAR(b.surface_pixels, 10000, 1500);
}

TEST(SceneBudget, AnIsolatedPointDoesNotClaimTheEmptySpaceAroundIt) {
  std::vector<Eigen::Vector3d> pts = grid_wall(1.0, 0.01);
  const SceneBudget clean = derive_scene_budget(pts, {camera_at(0)});
  pts.emplace_back(0.3, 0.3, 1.0);  // a stray point 1 m in front of the wall, its nearest neighbours 1 m off
  const SceneBudget stray = derive_scene_budget(pts, {camera_at(0)});
  EXPECT_LT(stray.surface_pixels, clean.surface_pixels * 1.01);
}

TEST(SceneBudget, PointsOutsideEveryViewOrNotFiniteAreLeftOut) {
  std::vector<Eigen::Vector3d> pts = grid_wall(1.0, 0.01);
  const SceneBudget clean = derive_scene_budget(pts, {camera_at(0)});
  pts.emplace_back(0, 0, -1.0);  // behind the camera
  pts.emplace_back(50, 0, 2.0);  // beside the image
  pts.emplace_back(std::numeric_limits<double>::quiet_NaN(), 0, 2.0);
  const SceneBudget b = derive_scene_budget(pts, {camera_at(0)});
  EXPECT_EQ(b.points, clean.points + 3);
  EXPECT_EQ(b.points_seen, clean.points_seen);
  EXPECT_DOUBLE_EQ(b.surface_pixels, clean.surface_pixels);
}

TEST(SceneBudget, NoPointInAnyViewIsAnErrorThatSaysSo) {
  try {
    derive_scene_budget({Eigen::Vector3d(0, 0, -1)}, {camera_at(0)});
    FAIL() << "expected std::invalid_argument";
  } catch (const std::invalid_argument& e) {
    EXPECT_NE(std::string(e.what()).find("inside a training view"), std::string::npos) << e.what();
  }
  EXPECT_THROW(derive_scene_budget({}, {camera_at(0)}), std::invalid_argument);
}

TEST(SceneBudget, CoincidentPointsGiveTheFloorNotNaN) {
  const std::vector<Eigen::Vector3d> pts(100, Eigen::Vector3d(0, 0, 2));
  const SceneBudget b = derive_scene_budget(pts, {camera_at(0)});
  EXPECT_TRUE(std::isfinite(b.surface_pixels));
  EXPECT_EQ(b.gaussians, SceneBudgetOptions{}.min_gaussians);
  const SceneBudget lone = derive_scene_budget({Eigen::Vector3d(0, 0, 2)}, {camera_at(0)});
  EXPECT_EQ(lone.gaussians, SceneBudgetOptions{}.min_gaussians);
}

TEST(SceneBudget, TheBudgetStaysWithinItsLimits) {
  SceneBudgetOptions o;
  o.max_gaussians = 1500;
  EXPECT_EQ(derive_scene_budget(grid_wall(1.0, 0.01), {camera_at(0)}, o).gaussians, 1500u);
  o.pixels_per_gaussian = 0;
  EXPECT_THROW(derive_scene_budget(grid_wall(1.0, 0.01), {camera_at(0)}, o), std::invalid_argument);
}

}  // namespace
}  // namespace litgs::host
