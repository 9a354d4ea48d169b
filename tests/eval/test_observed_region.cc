// The region the training views observe: in the image, in front of the camera, not behind the first
// surface; and the coverage of the observed reference by Gaussian centres.
#include <gtest/gtest.h>

#include "host/eval/observed_region.h"

namespace litgs::host {
namespace {

// A camera at the origin looking down +z (identity rotation), 64x48 pixels, f = 50.
kernels::SplatCamera camera_at_origin() {
  kernels::SplatCamera c;
  c.fx = c.fy = 50;
  c.cx = 32;
  c.cy = 24;
  c.width = 64;
  c.height = 48;
  return c;
}

// A wall at z = 5 filling the view, sampled every 2 cm.
std::vector<Eigen::Vector3d> wall_at_five_metres() {
  std::vector<Eigen::Vector3d> wall;
  for (int i = -200; i <= 200; ++i)
    for (int j = -150; j <= 150; ++j) wall.emplace_back(0.02 * i, 0.02 * j, 5.0);
  return wall;
}

TEST(EvalObservedRegion, InFrontOfTheFirstSurfaceIsSeenBehindItAndOutsideTheImageAreNot) {
  const ObservedRegion region(wall_at_five_metres(), {camera_at_origin()}, {});
  EXPECT_TRUE(region.contains({0.1, 0.1, 5.0}));    // on the wall
  EXPECT_TRUE(region.contains({0.1, 0.1, 2.0}));    // a floater in front of it
  EXPECT_TRUE(region.contains({0.1, 0.1, 5.15}));   // within the margin (0.1 m + 2 % of 5 m)
  EXPECT_FALSE(region.contains({0.1, 0.1, 5.5}));   // behind the wall: never seen
  EXPECT_FALSE(region.contains({0.1, 0.1, -1.0}));  // behind the camera
  EXPECT_FALSE(region.contains({4.0, 0.1, 5.0}));   // outside the image (u = 32 + 50 * 0.8 = 72 >= 64)
}

TEST(EvalObservedRegion, NoViewsObserveNothing) {
  const ObservedRegion region(wall_at_five_metres(), {}, {});
  EXPECT_FALSE(region.contains({0.1, 0.1, 5.0}));
}

TEST(EvalObservedRegion, CoverageCountsTheSeenReferenceWithAGaussianNearby) {
  std::vector<Eigen::Vector3d> reference = wall_at_five_metres();
  const size_t wall_points = reference.size();
  reference.emplace_back(0, 0, 9);  // behind the wall: not observed, so not counted against coverage
  const ObservedRegionOptions o;
  const ObservedRegion region(reference, {camera_at_origin()}, o);
  // Gaussians cover the seen wall's left half (x < 0), one faint one sits on the right half, and one lies
  // behind the wall.
  std::vector<Eigen::Vector3d> centres;
  std::vector<double> opacities;
  for (int i = -150; i < 0; i += 3)
    for (int j = -110; j <= 110; j += 3) {
      centres.emplace_back(0.02 * i, 0.02 * j, 5.0);
      opacities.push_back(0.9);
    }
  centres.emplace_back(1.0, 0.0, 5.0);
  opacities.push_back(0.05);  // below coverage_min_opacity: in the region, covers nothing
  centres.emplace_back(0.0, 0.0, 8.0);
  opacities.push_back(0.9);
  std::vector<size_t> observed, inside;
  const RegionCoverage c = measure_region(region, reference, centres, opacities, o, observed, inside);
  EXPECT_EQ(c.reference_points, wall_points + 1);
  // The image sees |x| < 3.2 m, |y| < 2.4 m of the wall (the wall's +-3 m in y is not all seen).
  size_t in_view = 0;
  for (const Eigen::Vector3d& p : reference)
    if (p.z() == 5.0 && std::abs(p.x()) < 3.2 && std::abs(p.y()) < 2.4) ++in_view;
  const double seen = static_cast<double>(in_view);
  EXPECT_NEAR(static_cast<double>(c.reference_observed), seen, seen * 0.01);
  EXPECT_EQ(c.reference_observed, observed.size());
  EXPECT_EQ(c.gaussians, centres.size());
  EXPECT_EQ(c.gaussians_in_region, centres.size() - 1);  // all but the one behind the wall
  // Coverage by brute force over every pair, against the grid search.
  size_t covered = 0;
  for (size_t i : observed)
    for (size_t g = 0; g < centres.size(); ++g)
      if (opacities[g] >= o.coverage_min_opacity &&
          (centres[g] - reference[i]).norm() <= o.coverage_radius_m) {
        ++covered;
        break;
      }
  EXPECT_EQ(c.reference_covered, covered);
  EXPECT_GT(c.covered_fraction(), 0.3);  // about the left half
  EXPECT_LT(c.covered_fraction(), 0.6);
  EXPECT_NEAR(c.reference_observed_fraction(),
              static_cast<double>(c.reference_observed) / static_cast<double>(wall_points + 1), 1e-12);
}

TEST(EvalObservedRegion, BadOptionsAreNamed) {
  ObservedRegionOptions o;
  o.coverage_radius_m = 0;
  EXPECT_THROW(o.check(), std::invalid_argument);
  o = {};
  o.cell_px = 0;
  EXPECT_THROW(ObservedRegion({}, {}, o), std::invalid_argument);
  std::vector<size_t> a, b;
  EXPECT_THROW(measure_region(ObservedRegion({}, {}, {}), {}, {{0, 0, 1}}, {}, {}, a, b),
               std::invalid_argument);
}

}  // namespace
}  // namespace litgs::host
