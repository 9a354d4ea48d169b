// The refinement's parts: ATE (Umeyama) against known transforms and perturbations, the motion-adaptive
// and anchor weights, triangulation.
#include <gtest/gtest.h>

#include <random>

#include "host/refine/ate.h"
#include "host/refine/refine.h"
#include "host/refine/synthetic_tracks.h"
#include "host/refine/triangulate_track.h"
#include "host/refine/weights.h"
#include "refine_test_scene.h"

namespace litgs::host::refine {
namespace {

std::vector<io::TumPose> random_trajectory(size_t n, std::mt19937& rng) {
  std::normal_distribution<double> g;
  std::vector<io::TumPose> out;
  Eigen::Vector3d p = Eigen::Vector3d::Zero();
  for (size_t i = 0; i < n; ++i) {
    p += Eigen::Vector3d(1 + 0.3 * g(rng), 0.5 * g(rng), 0.2 * g(rng));
    io::TumPose t;
    t.t_s = static_cast<double>(i);
    t.p_world = p;
    out.push_back(t);
  }
  return out;
}

TEST(RefineAte, RecoversAKnownRigidAndSimilarityTransform) {
  std::mt19937 rng(1);
  const auto truth = random_trajectory(50, rng);
  const Eigen::Matrix3d R = Eigen::AngleAxisd(0.7, Eigen::Vector3d(1, 2, 3).normalized()).toRotationMatrix();
  const Eigen::Vector3d t(4, -2, 9);
  for (double s : {1.0, 2.5}) {
    auto est = truth;
    for (auto& p : est) p.p_world = s * (R * p.p_world) + t;
    const AteResult se3 =
        absolute_trajectory_error(est, truth, s == 1 ? AteAlignment::kSE3 : AteAlignment::kSim3);
    EXPECT_LT(se3.rmse_m, 1e-9);
    EXPECT_EQ(se3.pairs, 50u);
    EXPECT_NEAR(se3.alignment.s, 1 / s, 1e-12);
    EXPECT_LT((se3.alignment.R - R.transpose()).norm(), 1e-9);
  }
  // A scaled estimate under SE(3) keeps an error; Sim(3) removes it.
  auto est = truth;
  for (auto& p : est) p.p_world *= 1.1;
  EXPECT_GT(absolute_trajectory_error(est, truth, AteAlignment::kSE3).rmse_m, 0.1);
  EXPECT_LT(absolute_trajectory_error(est, truth, AteAlignment::kSim3).rmse_m, 1e-9);
}

TEST(RefineAte, NoPerturbedAlignmentDoesBetter) {
  std::mt19937 rng(2);
  std::normal_distribution<double> g;
  const auto truth = random_trajectory(40, rng);
  auto est = truth;
  for (auto& p : est) p.p_world += 0.3 * Eigen::Vector3d(g(rng), g(rng), g(rng));
  const AteResult best = absolute_trajectory_error(est, truth, AteAlignment::kSE3);
  for (int trial = 0; trial < 200; ++trial) {
    Similarity a = best.alignment;
    a.R = Eigen::AngleAxisd(0.01 * g(rng), Eigen::Vector3d(g(rng), g(rng), g(rng)).normalized()) * a.R;
    a.t += 0.01 * Eigen::Vector3d(g(rng), g(rng), g(rng));
    double sum2 = 0;
    for (size_t i = 0; i < est.size(); ++i)
      sum2 += (a.apply(est[i].p_world) - truth[i].p_world).squaredNorm();
    EXPECT_GE(std::sqrt(sum2 / static_cast<double>(est.size())), best.rmse_m - 1e-12);
  }
}

TEST(RefineAte, PairsByTimeAndHandlesUnknownRotations) {
  std::mt19937 rng(3);
  auto truth = random_trajectory(30, rng);
  for (auto& p : truth) p.has_rotation = false;
  auto est = truth;
  for (auto& p : est) p.t_s += 0.004;  // within the default 10 ms
  EXPECT_EQ(absolute_trajectory_error(est, truth, AteAlignment::kSE3).pairs, 30u);
  for (auto& p : est) p.t_s += 1.5;
  EXPECT_THROW(absolute_trajectory_error(est, truth, AteAlignment::kSE3), std::invalid_argument);
}

TEST(RefineWeights, AlphaFollowsMotionWithinItsBounds) {
  std::vector<CameraPose> poses;
  double x = 0;
  for (int i = 0; i < 60; ++i) {
    CameraPose c;
    c.t_s = 0.1 * i;
    x += (i >= 30 && i < 40) ? 0.5 : 0.1;  // a fast stretch
    c.p_world_cam = {x, 0, 0};
    poses.push_back(c);
  }
  WeightOptions o;
  const auto alpha = motion_alphas(motion_scores(poses), o);
  for (double a : alpha) {
    EXPECT_GE(a, o.alpha_min);
    EXPECT_LE(a, o.alpha_max);
  }
  EXPECT_GT(alpha[35], alpha[10] + 0.05);  // fast frames lean on the anchors more
  o.alpha_min = 0.8;
  o.alpha_max = 0.2;
  EXPECT_THROW(motion_alphas({0.0}, o), std::invalid_argument);
}

TEST(RefineWeights, AnchorWeightsAreNormalizedAndGuarded) {
  std::vector<AnchorPoint> a(5);
  for (size_t i = 0; i < a.size(); ++i)
    a[i].cov = Eigen::Matrix3d::Identity() * 1e-4 * static_cast<double>(i + 1);
  a[4].cov = Eigen::Vector3d(1e-4, 1e-4, 1e-20).asDiagonal();  // near singular
  const AnchorWeights w = anchor_weights(a, {});
  EXPECT_EQ(w.guarded, 1u);
  std::vector<double> sorted = w.weights;
  std::sort(sorted.begin(), sorted.end());
  EXPECT_DOUBLE_EQ(sorted[2], 1.0);
  // 1 / sqrt(det): the covariance twice as large per axis weighs 2^-1.5 as much.
  EXPECT_NEAR(w.weights[1] / w.weights[0], std::pow(2.0, -1.5), 1e-12);
  // The guarded one: sigma floored to 1 mm on its thin axis, finite.
  EXPECT_NEAR(w.weights[4] / w.weights[0], 1e-2 / std::sqrt(1e-6), 1e-6);
  for (double x : w.weights) EXPECT_TRUE(std::isfinite(x));
}

TEST(RefineWeights, AnchoredObservationsCarryAlphaOfTheFrame) {
  std::vector<TrackPoint> pts(6);
  for (size_t i = 0; i < pts.size(); ++i) {
    pts[i].obs.push_back({0, Eigen::Vector2d(10.0 * static_cast<double>(i), 0), true, 1});
    pts[i].obs.push_back({1, Eigen::Vector2d(10.0 * static_cast<double>(i), 5), true, 1});
  }
  pts[0].anchor = 0;
  pts[1].anchor = 1;
  const std::vector<double> alphas = {0.6, 0.6};
  assign_observation_weights(pts, alphas, {1.0, 3.0}, {});
  double anchored = 0, total = 0;
  for (const auto& p : pts) {
    total += p.obs[0].weight;
    if (p.anchor >= 0) anchored += p.obs[0].weight;
  }
  EXPECT_NEAR(total, 6.0, 1e-12);
  EXPECT_NEAR(anchored, 0.6 * 6.0, 1e-12);
  EXPECT_NEAR(pts[1].obs[0].weight / pts[0].obs[0].weight, 3.0, 1e-12);
  EXPECT_GT(pts[2].obs[0].weight, pts[5].obs[0].weight);  // nearer the anchors
}

TEST(RefineTriangulation, RecoversAPointAndRefusesNoParallax) {
  PinholeCamera c{200, 200, 160, 120, 320, 240};
  std::vector<CameraPose> poses(3);
  for (size_t i = 0; i < 3; ++i) poses[i].p_world_cam = {0.5 * static_cast<double>(i), 0, 0};
  const Eigen::Vector3d X(0.4, -0.2, 6);
  std::vector<Observation> obs;
  for (uint32_t i = 0; i < 3; ++i) {
    const Eigen::Vector3d q = X - poses[i].p_world_cam;
    obs.push_back({i, Eigen::Vector2d(200 * q.x() / q.z() + 160, 200 * q.y() / q.z() + 120), true, 1});
  }
  obs.push_back({1, Eigen::Vector2d(10, 10), true, 1});  // a wrong match in frame 1
  const auto T = triangulate(obs, poses, c);
  ASSERT_TRUE(T.has_value());
  EXPECT_LT((*T - X).norm(), 1e-9);
  for (auto& p : poses) p.p_world_cam.setZero();  // one centre: pure rotation
  EXPECT_FALSE(triangulate(obs, poses, c).has_value());
}

// The synthetic stand-in for the front end: an anchor is followed through every frame that sees it as one
// track (0), or tracked like any other feature for at most N frames and found again as a new track.
TEST(RefineSyntheticTracks, AnchorTracksLastAsLongAsAsked) {
  testing::TestScene scene;
  testing::TestSceneOptions o;
  o.tracks.tracks_per_frame = 0;  // anchors' tracks only
  testing::make_test_scene(scene, o);
  ASSERT_GT(scene.anchors_true.size(), 20u);
  SyntheticTrackOptions whole = o.tracks, bounded = o.tracks;
  whole.anchor_track_length = 0;
  bounded.anchor_track_length = 5;
  const auto one_each =
      synthetic_tracks(scene.world, scene.truth, scene.priors, scene.camera, scene.anchors_true, whole);
  const auto sightings =
      synthetic_tracks(scene.world, scene.truth, scene.priors, scene.camera, scene.anchors_true, bounded);
  EXPECT_LE(one_each.size(), scene.anchors_true.size());
  EXPECT_GT(sightings.size(), one_each.size()) << "a lost anchor is found again as a new track";
  size_t longest = 0, observations_whole = 0, observations_bounded = 0;
  for (const auto& t : one_each) {
    longest = std::max(longest, t.obs.size());
    observations_whole += t.obs.size();
  }
  EXPECT_GT(longest, 5u) << "the whole-sequence tracks are longer than the bounded ones";
  for (const auto& t : sightings) {
    EXPECT_GE(t.obs.size(), 2u);
    EXPECT_LE(t.obs.size(), 5u);
    EXPECT_LE(t.obs.back().frame - t.obs.front().frame, 4u) << "a sighting is consecutive frames";
    observations_bounded += t.obs.size();
  }
  EXPECT_GT(observations_bounded, observations_whole / 4) << "the sightings still cover the anchors";
}

// A point that a solve left behind a camera observing it has no reprojection error: it is counted, and the
// RMS and median are those of the other observations (they were infinite before).
TEST(RefineResiduals, APointBehindItsCameraIsCountedNotAveraged) {
  PinholeCamera camera;
  camera.fx = camera.fy = 100;
  camera.cx = camera.cy = 50;
  camera.width = camera.height = 100;
  std::vector<CameraPose> poses(3);  // all at the origin, looking along +z
  TrackPoint seen, behind;
  seen.X = Eigen::Vector3d(0, 0, 2);
  seen.obs = {{0, Eigen::Vector2d(53, 54)}, {1, Eigen::Vector2d(50, 50)}, {2, Eigen::Vector2d(53, 50)}};
  behind.X = Eigen::Vector3d(0, 0, -2);
  behind.obs = {{0, Eigen::Vector2d(50, 50)}, {1, Eigen::Vector2d(50, 50)}};
  const ResidualStats s = residual_stats({seen, behind}, poses, camera);
  EXPECT_EQ(s.observations, 5u);
  EXPECT_EQ(s.behind_camera, 2u);
  EXPECT_NEAR(s.reprojection_rms_px, std::sqrt((25.0 + 0.0 + 9.0) / 3), 1e-12);  // errors 5, 0, 3 px
  EXPECT_NEAR(s.reprojection_median_px, 3.0, 1e-12);
  EXPECT_EQ(s.anchored_observations, 0u);
}

// The anchored points' observations get their own RMS beside the overall one.
TEST(RefineResiduals, AnchoredObservationsHaveTheirOwnRms) {
  PinholeCamera camera;
  camera.fx = camera.fy = 100;
  camera.cx = camera.cy = 50;
  camera.width = camera.height = 100;
  std::vector<CameraPose> poses(2);  // at the origin, looking along +z
  TrackPoint plain, anchored;
  plain.X = anchored.X = Eigen::Vector3d(0, 0, 2);
  plain.obs = {{0, Eigen::Vector2d(50, 50)}, {1, Eigen::Vector2d(50, 50)}};     // errors 0, 0 px
  anchored.obs = {{0, Eigen::Vector2d(54, 53)}, {1, Eigen::Vector2d(50, 51)}};  // errors 5, 1 px
  anchored.anchor = 0;
  const ResidualStats s = residual_stats({plain, anchored}, poses, camera);
  EXPECT_EQ(s.observations, 4u);
  EXPECT_EQ(s.anchored_observations, 2u);
  EXPECT_NEAR(s.anchored_reprojection_rms_px, std::sqrt((25.0 + 1.0) / 2), 1e-12);
  EXPECT_NEAR(s.reprojection_rms_px, std::sqrt((25.0 + 1.0) / 4), 1e-12);
}

}  // namespace
}  // namespace litgs::host::refine
