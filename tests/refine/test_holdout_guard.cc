// The guard against a refinement that makes the poses worse (host/refine/holdout_guard.h): tracks held back
// from the solve judge it, without ground truth.
#include <gtest/gtest.h>

#include "host/refine/holdout_guard.h"
#include "host/refine/scan_check.h"
#include "refine_test_scene.h"

namespace litgs::host::refine::testing {
namespace {

TEST(RefineHoldoutGuard, HoldsBackEveryNthTrack) {
  std::vector<TrackPoint> points(20);
  for (size_t i = 0; i < points.size(); ++i) points[i].X = Eigen::Vector3d(static_cast<double>(i), 0, 0);
  HoldoutOptions o;
  o.every = 4;
  const std::vector<TrackPoint> held = hold_out_tracks(points, o);
  ASSERT_EQ(held.size(), 5u);
  EXPECT_EQ(points.size(), 15u);
  EXPECT_EQ(held[0].X.x(), 3);
  EXPECT_EQ(held[4].X.x(), 19);
  o.every = 1;
  EXPECT_THROW(hold_out_tracks(points, o), std::invalid_argument);
}

TEST(RefineHoldoutGuard, AGoodRefinementIsKeptAndExplainsTheHeldBackTracksBetter) {
  TestScene s;
  make_test_scene(s, {});
  std::vector<CameraPose> poses = s.input.priors;
  const RefineReport r = refine(s.input, poses, {});
  EXPECT_EQ(r.outcome, "refined");
  ASSERT_TRUE(r.holdout.measured);
  EXPECT_GT(r.holdout.tracks_used, 10u);
  EXPECT_LT(r.holdout.refined_median_px, r.holdout.prior_median_px);
  EXPECT_LT(ate(poses, s.truth), ate(s.input.priors, s.truth));
}

// Once the held-back tracks have judged the solve worth keeping, it is solved again with them in it: the
// output is the solve over every track (the same as one that held none back), the verdict the guard's.
TEST(RefineHoldoutGuard, AKeptRefinementIsSolvedAgainWithEveryTrack) {
  TestScene s, all;
  make_test_scene(s, {});
  make_test_scene(all, {});
  const size_t tracks = s.input.points.size();
  std::vector<CameraPose> poses = s.input.priors, every = all.input.priors;
  const RefineReport r = refine(s.input, poses, {});
  ASSERT_EQ(r.outcome, "refined");
  ASSERT_TRUE(r.holdout.measured);
  EXPECT_EQ(s.input.points.size(), tracks) << "the held-back tracks are back in the output";
  EXPECT_NE(r.notes.at(0).find("then solved again with every track"), std::string::npos) << r.notes.at(0);
  RefineOptions unguarded;
  unguarded.holdout.every = 0;
  refine(all.input, every, unguarded);
  for (size_t f = 0; f < poses.size(); ++f)
    EXPECT_LT((poses[f].p_world_cam - every[f].p_world_cam).norm(), 1e-9) << "frame " << f;
}

// Built to fail: the tracks the solve sees are corrupted in the second half of the sequence (every
// observation 12 px to the right, as a wrong time offset or a bad calibration would do), the held-back ones
// are not. The solve turns those cameras to fit; the held-back tracks show it, and the priors are kept.
TEST(RefineHoldoutGuard, ARefinementThatMakesThePosesWorseKeepsThePriors) {
  TestScene s;
  TestSceneOptions so;
  so.drift_per_m = 0.0005;
  so.rotation_drift_per_m = 0.0002;
  so.anchors = 0;
  make_test_scene(s, so);
  const HoldoutOptions guard;
  // Every track the guard does not hold back, 12 px to the right from frame 20 on.
  const auto corrupt = [&guard](std::vector<TrackPoint>& points) {
    for (size_t i = 0; i < points.size(); ++i) {
      if (i % guard.every == guard.every - 1) continue;  // held back: left true
      for (auto& ob : points[i].obs)
        if (ob.frame >= 20) ob.uv.x() += 12;
    }
  };
  corrupt(s.input.points);
  const std::vector<CameraPose> priors = s.input.priors;
  std::vector<CameraPose> poses = priors;
  RefineOptions o;
  o.use_planes = false;  // nothing else to hold the cameras: the corrupted tracks win the solve
  const RefineReport r = refine(s.input, poses, o);
  std::cout << "  " << r.status << "\n";
  ASSERT_TRUE(r.holdout.measured);
  EXPECT_GT(r.holdout.refined_median_px, r.holdout.prior_median_px);
  EXPECT_EQ(r.outcome, "kept the priors");
  for (size_t f = 0; f < poses.size(); ++f)
    EXPECT_EQ(poses[f].p_world_cam, priors[f].p_world_cam) << "frame " << f;

  // The same solve without the guard returns the corrupted poses: what the guard prevented.
  TestScene s2;
  make_test_scene(s2, so);
  corrupt(s2.input.points);
  std::vector<CameraPose> unguarded = s2.input.priors;
  o.holdout.every = 0;
  const RefineReport r2 = refine(s2.input, unguarded, o);
  EXPECT_EQ(r2.outcome, "refined");
  EXPECT_GT(ate(unguarded, s2.truth), ate(s2.input.priors, s2.truth));
}

// The LiDAR side: an empty scan (a dropped LiDAR message) counts for nothing; the scans of a plane taken
// through poses shifted off it are worse than through the true poses.
TEST(RefineScanCheck, AnEmptyScanCountsForNothingAndAShiftedPoseIsWorse) {
  std::vector<Eigen::Vector3d> wall;
  for (int i = 0; i < 40; ++i)
    for (int j = 0; j < 20; ++j) wall.push_back(Eigen::Vector3d(0.1 * i, 5.0, 0.1 * j));
  const PlanarMap map = fit_planes(wall, {});
  Eigen::Matrix4d shifted = Eigen::Matrix4d::Identity();
  shifted(1, 3) = 0.05;  // 5 cm towards the wall
  std::vector<CheckedScan> scans(2);
  scans[0].T_world_lidar_refined = shifted;
  scans[1].T_world_lidar_refined = shifted;
  for (int i = 5; i < 35; ++i) scans[1].points_lidar.push_back(Eigen::Vector3d(0.1 * i, 5.0, 0.95));
  const ScanVerdict v = judge_on_scans(map, map, scans, {});
  EXPECT_EQ(v.scans, 1u);  // the empty one is skipped
  ASSERT_TRUE(v.measured);
  EXPECT_LT(v.prior_mean_m, 1e-6);
  EXPECT_NEAR(v.refined_mean_m, 0.05, 1e-6);
  EXPECT_FALSE(v.keep_refined);
  const ScanVerdict none = judge_on_scans(map, map, {scans[0]}, {});
  EXPECT_FALSE(none.measured);
  EXPECT_TRUE(none.keep_refined);
}

// The odometry built the scene's map, so a held-out scan placed through the odometry shares its error and
// lands on it: judged against that one map, a correction would always look worse. Each trajectory against
// the map it builds itself from the other scans: a consistent correction passes, and a refined pose that
// puts its scan off the surfaces its own other scans measured still fails.
TEST(RefineScanCheck, EachTrajectoryAgainstItsOwnMapDoesNotFavourTheOneThatBuiltTheScenesMap) {
  const auto wall_at = [](double y) {
    std::vector<Eigen::Vector3d> wall;
    for (int i = 0; i < 40; ++i)
      for (int j = 0; j < 20; ++j) wall.push_back(Eigen::Vector3d(0.1 * i, y, 0.1 * j));
    return fit_planes(wall, {});
  };
  const PlanarMap through_priors = wall_at(5.05), through_refined = wall_at(5.0);  // priors 5 cm off
  std::vector<CheckedScan> scans(1);
  for (int i = 5; i < 35; ++i) scans[0].points_lidar.push_back(Eigen::Vector3d(0.1 * i, 5.0, 0.95));
  scans[0].T_world_lidar_prior(1, 3) = 0.05;  // the priors' error, shared by their map
  const ScanVerdict one_map = judge_on_scans(through_priors, through_priors, scans, {});
  EXPECT_FALSE(one_map.keep_refined);  // the bias
  const ScanVerdict own_maps = judge_on_scans(through_priors, through_refined, scans, {});
  ASSERT_TRUE(own_maps.measured);
  EXPECT_NEAR(own_maps.prior_mean_m, 0, 1e-6);
  EXPECT_NEAR(own_maps.refined_mean_m, 0, 1e-6);
  EXPECT_TRUE(own_maps.keep_refined);
  scans[0].T_world_lidar_refined(1, 3) = -0.04;  // a refined pose that breaks with its own map
  const ScanVerdict inconsistent = judge_on_scans(through_priors, through_refined, scans, {});
  EXPECT_NEAR(inconsistent.refined_mean_m, 0.04, 1e-6);
  EXPECT_FALSE(inconsistent.keep_refined);
}

}  // namespace
}  // namespace litgs::host::refine::testing
