// The refinement's associations (host/refine/association.h) on a built case: a wall at z = 5 m seen by four
// cameras looking down +z, tracks observed exactly. Anchors: the chi^2 gate, the occlusion check, one track
// per anchor and ambiguity; planes: the two ways in (depth image, nearest point) and the shrinking radius.
#include <gtest/gtest.h>

#include "host/refine/association.h"

namespace litgs::host::refine {
namespace {

struct WallScene {
  PinholeCamera camera{200, 200, 159.5, 127.5, 320, 256};
  std::vector<CameraPose> poses;
  PlanarMap map;
  WallScene() {
    for (int f = 0; f < 4; ++f) poses.push_back({0.1 * f, Eigen::Quaterniond::Identity(), {0.2 * f, 0, 0}});
    std::vector<Eigen::Vector3d> wall;
    for (int i = -60; i <= 60; ++i)
      for (int j = -50; j <= 50; ++j) wall.emplace_back(0.05 * i, 0.05 * j, 5.0);
    map = fit_planes(wall, {});
  }
  // A track of X seen exactly by every frame (or the first `frames`).
  TrackPoint track(const Eigen::Vector3d& X, size_t frames = 4) const {
    TrackPoint t;
    t.X = X;
    for (size_t f = 0; f < frames; ++f) {
      const Eigen::Vector3d x = poses[f].q_world_cam.conjugate() * (X - poses[f].p_world_cam);
      t.obs.push_back({static_cast<uint32_t>(f),
                       {camera.fx * x.x() / x.z() + camera.cx, camera.fy * x.y() / x.z() + camera.cy}});
    }
    return t;
  }
};

AnchorPoint anchor_at(const Eigen::Vector3d& p, double sigma_m) {
  return {p, Eigen::Matrix3d::Identity() * sigma_m * sigma_m};
}

TEST(RefineAssociateAnchors, AnAnchorOnATrackIsTakenAndOneOffAlongTheRayFailsTheGate) {
  const WallScene s;
  std::vector<TrackPoint> points = {s.track({0.3, 0.2, 5.0}), s.track({-0.5, 0.4, 5.0})};
  // Anchor 0 on track 0 (within 5 mm); anchor 1 on track 1's first ray but 30 cm nearer: within 1.5 px of
  // the track in every frame (0.6 m of baseline at 5 m), but 15 sigma from its point.
  const Eigen::Vector3d nearer =
      s.poses[0].p_world_cam + (points[1].X - s.poses[0].p_world_cam) * (4.7 / 5.0);
  const std::vector<AnchorPoint> anchors = {anchor_at({0.305, 0.2, 5.0}, 0.02), anchor_at(nearer, 0.02)};
  const AnchorAssociationReport r =
      associate_anchors(points, anchors, s.poses, s.camera, &s.map, AnchorAssociationOptions{});
  EXPECT_EQ(points[0].anchor, 0);
  EXPECT_EQ(points[1].anchor, -1);
  EXPECT_EQ(r.anchored_tracks, 1u);
  EXPECT_EQ(r.ambiguous_anchors, 0u);
  // The pixels alone would take it: with a gate wide enough for the 30 cm, it is.
  AnchorAssociationOptions loose;
  loose.gate_chi2 = 1e6;
  associate_anchors(points, anchors, s.poses, s.camera, &s.map, loose);
  EXPECT_EQ(points[1].anchor, 1);
}

TEST(RefineAssociateAnchors, TwoTracksInsideOneAnchorsGateMakeItAmbiguous) {
  const WallScene s;
  // Two tracks 1 cm apart (1.25 px at 5 m, within the 3 px radius), an anchor between them, 2 cm sigma.
  std::vector<TrackPoint> points = {s.track({0.30, 0.2, 5.0}), s.track({0.31, 0.2, 5.0})};
  const std::vector<AnchorPoint> anchors = {anchor_at({0.305, 0.2, 5.0}, 0.02)};
  const AnchorAssociationReport r =
      associate_anchors(points, anchors, s.poses, s.camera, &s.map, AnchorAssociationOptions{});
  EXPECT_EQ(r.ambiguous_anchors, 1u);
  EXPECT_EQ(points[0].anchor, -1);
  EXPECT_EQ(points[1].anchor, -1);
  // Without the rejection the anchor goes to one track only: the nearer in pixels (a tie on votes).
  AnchorAssociationOptions keep;
  keep.reject_ambiguous = false;
  const AnchorAssociationReport k = associate_anchors(points, anchors, s.poses, s.camera, &s.map, keep);
  EXPECT_EQ(k.anchored_tracks, 1u);
  EXPECT_EQ(points[0].anchor + points[1].anchor, -1);  // one of them 0, the other -1
}

TEST(RefineAssociateAnchors, AnAnchorBehindTheMapsSurfaceIsHidden) {
  const WallScene s;
  // A track on a point 1 m behind the wall (as if seen through a window the map does not have), its anchor
  // on it: the map's depth says the wall is in front, so no frame sees the anchor.
  std::vector<TrackPoint> points = {s.track({0.3, 0.2, 6.0})};
  const std::vector<AnchorPoint> anchors = {anchor_at({0.3, 0.2, 6.0}, 0.02)};
  const AnchorAssociationReport r =
      associate_anchors(points, anchors, s.poses, s.camera, &s.map, AnchorAssociationOptions{});
  EXPECT_EQ(points[0].anchor, -1);
  EXPECT_EQ(r.occluded_projections, 4u);
  // Without a map there is no occlusion check.
  associate_anchors(points, anchors, s.poses, s.camera, nullptr, AnchorAssociationOptions{});
  EXPECT_EQ(points[0].anchor, 0);
}

TEST(RefinePlaneAssociator, ShortTracksGoThroughTheDepthImageLongOnesThroughTheNearestPoint) {
  const WallScene s;
  const PlaneAssociator associator(s.map, s.camera);
  std::vector<TrackPoint> points = {s.track({0.3, 0.2, 5.02}, 3), s.track({-0.4, 0.1, 4.97}, 4),
                                    s.track({0.2, -0.3, 5.01})};
  PlaneAssociationOptions o;
  o.long_track = 4;
  const PlaneAssociationReport r = associator.associate(points, s.poses, 0, o);
  EXPECT_EQ(r.by_depth_image, 1u);
  EXPECT_EQ(r.by_nearest_point, 2u);
  EXPECT_EQ(r.unassociated, 0u);
  for (const TrackPoint& p : points) {
    ASSERT_TRUE(p.has_plane);
    EXPECT_NEAR(std::abs(p.plane.n.z()), 1.0, 1e-3);  // the wall's normal
    EXPECT_NEAR(p.plane.l.z(), 5.0, 1e-3);
    // The signed distance the bundle adjustment will see is the point's offset from the wall.
    EXPECT_NEAR(std::abs(p.plane.n.dot(p.X - p.plane.l)), std::abs(p.X.z() - 5.0), 1e-3);
  }
}

TEST(RefinePlaneAssociator, TheRadiusShrinksOverTheRounds) {
  const WallScene s;
  const PlaneAssociator associator(s.map, s.camera);
  std::vector<TrackPoint> points = {s.track({0.3, 0.2, 5.2})};  // 20 cm off the wall
  const PlaneAssociationOptions o;                              // 0.5 m, halved per round, 5 cm at least
  EXPECT_EQ(associator.associate(points, s.poses, 0, o).unassociated, 0u);
  EXPECT_TRUE(points[0].has_plane);
  const PlaneAssociationReport third = associator.associate(points, s.poses, 2, o);  // 12.5 cm
  EXPECT_NEAR(third.radius_m, 0.125, 1e-12);
  EXPECT_EQ(third.unassociated, 1u);
  EXPECT_FALSE(points[0].has_plane);
}

}  // namespace
}  // namespace litgs::host::refine
