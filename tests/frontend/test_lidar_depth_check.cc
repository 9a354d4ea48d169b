// Match verification by the LiDAR map (host/frontend/lidar_depth_check.h): a keypoint lifted to the map's
// depth must land near its match. Exact inputs: a wall of map points in front of two cameras.
#include <gtest/gtest.h>

#include <Eigen/Geometry>
#include <cmath>

#include "host/frontend/lidar_depth_check.h"

namespace litgs::host::frontend {
namespace {

const PinholeK kK{300, 300, 159.5, 127.5};
constexpr uint32_t kWidth = 320, kHeight = 256;

// Map samples every 2 cm on the plane z = depth (world frame), over x, y in [-3, 3].
std::vector<Eigen::Vector3d> wall(double depth, double x_min = -3, double x_max = 3) {
  std::vector<Eigen::Vector3d> out;
  for (double x = x_min; x <= x_max; x += 0.02)
    for (double y = -3; y <= 3; y += 0.02) out.emplace_back(x, y, depth);
  return out;
}

struct Camera {
  Eigen::Matrix3d R = Eigen::Matrix3d::Identity();
  Eigen::Vector3d t = Eigen::Vector3d::Zero();  // camera from world; centre at -t
  Eigen::Vector2d project(const Eigen::Vector3d& X) const {
    const Eigen::Vector3d c = R * X + t;
    return {kK.fx * c.x() / c.z() + kK.cx, kK.fy * c.y() / c.z() + kK.cy};
  }
};

// Two cameras 0.3 m apart along x, looking along +z.
const Camera kA{}, kB{Eigen::Matrix3d::Identity(), Eigen::Vector3d(-0.3, 0, 0)};

TEST(FrontendLidarCheck, TheDepthImageHoldsTheNearestSurface) {
  std::vector<Eigen::Vector3d> map = wall(8.0);
  const std::vector<Eigen::Vector3d> near = wall(5.0, -0.5, 0.5);
  map.insert(map.end(), near.begin(), near.end());
  const LidarDepthImage depth(map, kA.R, kA.t, kK, kWidth, kHeight, {});
  ASSERT_FALSE(depth.candidates(kA.project({0, 0, 5})).empty());
  for (double d : depth.candidates(kA.project({0, 0, 5})))
    EXPECT_NEAR(d, 5.0, 1e-6);  // the wall behind hidden
  ASSERT_FALSE(depth.candidates(kA.project({2, 0, 8})).empty());
  for (double d : depth.candidates(kA.project({2, 0, 8}))) EXPECT_NEAR(d, 8.0, 1e-6);
  // Behind the camera and outside the image nothing lands; an empty map judges nothing.
  EXPECT_TRUE(LidarDepthImage({{0, 0, -5}, {100, 0, 5}}, kA.R, kA.t, kK, kWidth, kHeight, {})
                  .candidates({159.5, 127.5})
                  .empty());
}

TEST(FrontendLidarCheck, RepetitiveTextureMatchedOnePeriodOffIsContradicted) {
  // Bricks every 0.25 m on a wall 5 m away: a brick and its right neighbour lie on one epipolar line (the
  // baseline is along x), so the essential matrix cannot tell them apart; the map's depth can.
  const std::vector<Eigen::Vector3d> map = wall(5.0);
  const LidarDepthImage da(map, kA.R, kA.t, kK, kWidth, kHeight, {}),
      db(map, kB.R, kB.t, kK, kWidth, kHeight, {});
  const Eigen::Vector3d brick(0.5, 0.1, 5), neighbour(0.75, 0.1, 5);
  const Eigen::Vector2d xa = kA.project(brick), xb_true = kB.project(brick), xb_wrong = kB.project(neighbour);
  ASSERT_NEAR(xb_true.y(), xb_wrong.y(), 1e-9);  // same epipolar line
  const DepthView a{kA.R, kA.t, xa, da};
  const DepthView b_true{kB.R, kB.t, xb_true, db}, b_wrong{kB.R, kB.t, xb_wrong, db};
  const std::optional<double> t_true = lidar_transfer_px(match_transfers(a, b_true, kK).ab);
  ASSERT_TRUE(t_true.has_value());
  // Cells of 4 px on a wall 5 m deep: every candidate depth is the wall's, so the transfer is exact.
  EXPECT_NEAR(*t_true, 0.0, 1e-6);
  EXPECT_NEAR(*lidar_transfer_px(match_transfers(a, b_wrong, kK).ab), 300 * 0.25 / 5,
              1e-6);  // one period: 15 px
  EXPECT_FALSE(contradicted_by_lidar(match_transfers(a, b_true, kK), 8));
  EXPECT_TRUE(contradicted_by_lidar(match_transfers(a, b_wrong, kK), 8));
  EXPECT_FALSE(
      contradicted_by_lidar(match_transfers(a, b_wrong, kK), 16));  // a bound wider than the period keeps it
}

TEST(FrontendLidarCheck, AMatchBesideADepthEdgeIsKept) {
  // A pillar 3 m away in front of the wall at 8 m: a wall point just beside the pillar's edge has both
  // depths among its candidates, and the wall's explains the match.
  std::vector<Eigen::Vector3d> map = wall(8.0);
  const std::vector<Eigen::Vector3d> pillar = wall(3.0, -1.0, 0.0);
  map.insert(map.end(), pillar.begin(), pillar.end());
  const LidarDepthImage da(map, kA.R, kA.t, kK, kWidth, kHeight, {}),
      db(map, kB.R, kB.t, kK, kWidth, kHeight, {});
  const Eigen::Vector3d X(0.03 * 8 / 3, 0.2, 8);  // 3 px right of the pillar's edge in image a
  const Eigen::Vector2d xa = kA.project(X), xb = kB.project(X);
  std::vector<double> near_edge = da.candidates(xa);
  ASSERT_GE(near_edge.size(), 2u);
  EXPECT_NEAR(*std::min_element(near_edge.begin(), near_edge.end()), 3.0, 1e-6);
  EXPECT_FALSE(contradicted_by_lidar(match_transfers({kA.R, kA.t, xa, da}, {kB.R, kB.t, xb, db}, kK), 8));
}

TEST(FrontendLidarCheck, OnOneSlantedSurfaceOnlyTheKeypointsOwnCellIsACandidate) {
  // A side wall (x = 1) seen at a grazing angle: the neighbouring cells' depths differ from the keypoint's
  // by 5-8 %, the same surface. Taken as candidates they would let a match one period along the wall
  // pass; only the keypoint's own cell is.
  std::vector<Eigen::Vector3d> map;
  for (double z = 2; z <= 12; z += 0.01)
    for (double y = -1; y <= 1; y += 0.01) map.emplace_back(1.0, y, z);
  const LidarDepthImage da(map, kA.R, kA.t, kK, kWidth, kHeight, {});
  const Eigen::Vector2d xa = kA.project({1.0, 0.1, 5.0});  // 60 px right of the centre
  const std::vector<double> own = da.candidates(xa);
  ASSERT_EQ(own.size(), 1u);
  // The nearest sample in the keypoint's 4-px cell, which spans the wall from 4.69 to 5 m.
  EXPECT_NEAR(own[0], 300.0 / 64, 0.01);
  // Counting every neighbour of another depth as another surface (edge_ratio 0), the six cells of the
  // columns beside it join (those above and below lie at its own depth).
  LidarCheckOptions every_neighbour;
  every_neighbour.edge_ratio = 0.0;
  EXPECT_EQ(LidarDepthImage(map, kA.R, kA.t, kK, kWidth, kHeight, every_neighbour).candidates(xa).size(), 7u);
}

TEST(FrontendLidarCheck, APairsCommonPriorErrorIsRemovedBeforeTheBound) {
  // Camera b's prior is turned 0.02 rad about y from where it was: every true match of the pair transfers
  // about 6 px off, beyond a 3 px bound. Their common offset removed, the true matches pass and a brick
  // matched one period (15 px) off is still contradicted.
  const std::vector<Eigen::Vector3d> map = wall(5.0);
  const Camera b_prior{Eigen::AngleAxisd(0.02, Eigen::Vector3d::UnitY()).toRotationMatrix() * kB.R,
                       Eigen::AngleAxisd(0.02, Eigen::Vector3d::UnitY()).toRotationMatrix() * kB.t};
  const LidarDepthImage da(map, kA.R, kA.t, kK, kWidth, kHeight, {}),
      db(map, b_prior.R, b_prior.t, kK, kWidth, kHeight, {});
  std::vector<Eigen::Vector2d> xa, xb;  // true matches: the truth's projections (the keypoints)
  for (double x = -0.6; x <= 0.61; x += 0.2)
    for (double y = -0.4; y <= 0.41; y += 0.2) {
      xa.push_back(kA.project({x, y, 5}));
      xb.push_back(kB.project({x, y, 5}));
    }
  std::vector<MatchTransfers> matches;
  for (size_t k = 0; k < xa.size(); ++k)
    matches.push_back(match_transfers({kA.R, kA.t, xa[k], da}, {b_prior.R, b_prior.t, xb[k], db}, kK));
  const Eigen::Vector2d wrong_b = kB.project({0.45, 0.1, 5});  // the brick at x = 0.2 matched one period off
  const Eigen::Vector2d brick_a = kA.project({0.2, 0.1, 5});
  const MatchTransfers wrong =
      match_transfers({kA.R, kA.t, brick_a, da}, {b_prior.R, b_prior.t, wrong_b, db}, kK);
  matches.push_back(wrong);
  size_t beyond_without_offset = 0;
  for (const MatchTransfers& m : matches) beyond_without_offset += contradicted_by_lidar(m, 3);
  EXPECT_GE(beyond_without_offset, matches.size() - 1);  // the prior's error alone exceeds the bound
  const PairTransferOffset offset = pair_transfer_offset(matches, 15);
  EXPECT_GT(offset.ab.norm(), 5.0);
  for (size_t k = 0; k + 1 < matches.size(); ++k)
    EXPECT_FALSE(contradicted_by_lidar(matches[k], 3, offset.ab, offset.ba)) << k;
  EXPECT_TRUE(contradicted_by_lidar(wrong, 3, offset.ab, offset.ba));
  // Too few matches to judge the pair by: no offset.
  EXPECT_EQ(pair_transfer_offset(matches, matches.size() + 1).ab, Eigen::Vector2d::Zero());
}

TEST(FrontendLidarCheck, WithoutMapDepthTheMatchCannotBeJudgedAndIsKept) {
  const LidarDepthImage empty({}, kA.R, kA.t, kK, kWidth, kHeight, {});
  const Eigen::Vector2d xa(100, 100), xb(300, 20);  // far from consistent, but nothing to judge by
  const MatchTransfers m = match_transfers({kA.R, kA.t, xa, empty}, {kB.R, kB.t, xb, empty}, kK);
  EXPECT_FALSE(lidar_transfer_px(m.ab).has_value());
  EXPECT_FALSE(lidar_transfer_px(m.ba).has_value());
  EXPECT_FALSE(contradicted_by_lidar(m, 8));
}

TEST(FrontendLidarCheck, BadOptionsAreRefusedByName) {
  LidarCheckOptions o;
  o.max_transfer_px = 0;
  try {
    o.check();
    FAIL() << "a zero bound was accepted";
  } catch (const std::invalid_argument& e) {
    EXPECT_NE(std::string(e.what()).find("max_transfer_px"), std::string::npos);
  }
  o = {};
  o.cell_px = 0;
  EXPECT_THROW(o.check(), std::invalid_argument);
}

}  // namespace
}  // namespace litgs::host::frontend
