// The front end's parts on small exact inputs: triangulation, union-find tracks, grid bucketing, the
// percentile stretch, the frozen-frame detector, verification of outliers, pair selection.
#include <gtest/gtest.h>

#include <Eigen/Geometry>
#include <algorithm>
#include <cmath>
#include <numeric>
#include <random>

#include "host/frontend/features.h"
#include "host/frontend/frozen_frames.h"
#include "host/frontend/intensity.h"
#include "host/frontend/pair_selection.h"
#include "host/frontend/tracks.h"
#include "host/frontend/triangulation.h"
#include "host/frontend/verification.h"

namespace litgs::host::frontend {
namespace {

constexpr double kF = 500;  // focal length of the synthetic views, pixels

// A camera at `centre` looking at `target` (x_cam = R x_world + t).
TriangulationView look_at(const Eigen::Vector3d& centre, const Eigen::Vector3d& target) {
  const Eigen::Vector3d z = (target - centre).normalized();
  const Eigen::Vector3d x = Eigen::Vector3d::UnitY().cross(z).normalized();
  const Eigen::Vector3d y = z.cross(x);
  TriangulationView v;
  v.R_cam_world.row(0) = x;
  v.R_cam_world.row(1) = y;
  v.R_cam_world.row(2) = z;
  v.t_cam_world = -v.R_cam_world * centre;
  return v;
}

void observe(TriangulationView& v, const Eigen::Vector3d& X, const Eigen::Vector2d& noise_px) {
  const Eigen::Vector3d c = v.R_cam_world * X + v.t_cam_world;
  v.xy = c.head<2>() / c.z() + noise_px / kF;
}

TEST(FrontendTriangulation, RecoversANoisyPointWithinItsNoise) {
  const Eigen::Vector3d X(0.3, -0.2, 6.0);
  std::mt19937 rng(7);
  std::normal_distribution<double> noise(0.0, 0.5);  // pixels
  std::vector<TriangulationView> views;
  for (int i = 0; i < 6; ++i) {
    views.push_back(look_at(Eigen::Vector3d(-1.5 + 0.6 * i, 0.1 * i, 0), X));
    observe(views.back(), X, {noise(rng), noise(rng)});
  }
  const TriangulatedPoint p = triangulate(views, kF, kF, {});
  ASSERT_EQ(p.outcome, TriangulationOutcome::kOk);
  EXPECT_EQ(p.views.size(), 6u);
  // Depth uncertainty for 0.5 px over a 3 m baseline at 6 m: about 6 * 0.5 / 500 * 6 / 3 = 1 cm.
  EXPECT_LT((p.xyz - X).norm(), 0.03);
  EXPECT_GT(p.mean_error_px, 0.05);
  EXPECT_LT(p.mean_error_px, 1.5);
}

TEST(FrontendTriangulation, DropsTheViewThatDisagrees) {
  const Eigen::Vector3d X(0, 0, 5);
  std::vector<TriangulationView> views;
  for (int i = 0; i < 4; ++i) {
    views.push_back(look_at(Eigen::Vector3d(-1 + 0.7 * i, 0, 0), X));
    observe(views.back(), X, {0, 0});
  }
  views[2].xy += Eigen::Vector2d(30, -20) / kF;  // a wrong match
  const TriangulatedPoint p = triangulate(views, kF, kF, {});
  ASSERT_EQ(p.outcome, TriangulationOutcome::kOk);
  EXPECT_EQ(p.views, (std::vector<size_t>{0, 1, 3}));
  EXPECT_LT((p.xyz - X).norm(), 1e-6);
  EXPECT_LT(p.mean_error_px, 1e-6);
}

TEST(FrontendTriangulation, PureRotationGivesNoPoint) {
  const Eigen::Vector3d X(0.5, 0, 5);
  TriangulationView a = look_at(Eigen::Vector3d::Zero(), Eigen::Vector3d(0, 0, 1));
  TriangulationView b = look_at(Eigen::Vector3d::Zero(), Eigen::Vector3d(0.2, 0, 1));
  observe(a, X, {0, 0});
  observe(b, X, {0, 0});
  TriangulationOptions two_views;
  two_views.min_views = 2;
  const TriangulatedPoint p = triangulate({a, b}, kF, kF, two_views);
  EXPECT_EQ(p.outcome, TriangulationOutcome::kNoAngle);
  EXPECT_EQ(triangulate({a, b}, kF, kF, {}).outcome, TriangulationOutcome::kTooFewViews);  // 3 by default
  EXPECT_TRUE(p.xyz.allFinite());
}

TEST(FrontendTriangulation, PointBehindTheCamerasIsRejected) {
  // Rays that meet only behind both cameras (the point (0, 0, -5) projected through the cameras).
  TriangulationView a = look_at(Eigen::Vector3d(-1, 0, 0), Eigen::Vector3d(-1, 0, 1));
  TriangulationView b = look_at(Eigen::Vector3d(1, 0, 0), Eigen::Vector3d(1, 0, 1));
  a.xy = {-0.2, 0};  // (0, 0, -5) from a: x/z = 1 / -5
  b.xy = {0.2, 0};
  TriangulationOptions two_views;
  two_views.min_views = 2;
  const TriangulatedPoint p = triangulate({a, b}, kF, kF, two_views);
  EXPECT_NE(p.outcome, TriangulationOutcome::kOk);
}

// The refinement's estimator (the midpoint of the rays, pairs spread over the views) against the front
// end's (DLT and Gauss-Newton) on one noisy track: both within the noise, and near each other.
TEST(FrontendTriangulation, MidpointAndLinearAgreeWithinTheNoise) {
  const Eigen::Vector3d X(0.3, -0.2, 6.0);
  std::mt19937 rng(11);
  std::normal_distribution<double> noise(0.0, 0.5);  // pixels
  std::vector<TriangulationView> views;
  for (int i = 0; i < 6; ++i) {
    views.push_back(look_at(Eigen::Vector3d(-1.5 + 0.6 * i, 0.1 * i, 0), X));
    observe(views.back(), X, {noise(rng), noise(rng)});
  }
  const TriangulatedPoint linear = triangulate(views, kF, kF, {});
  const TriangulatedPoint midpoint = triangulate(views, kF, kF, TriangulationOptions::refinement());
  ASSERT_EQ(linear.outcome, TriangulationOutcome::kOk);
  ASSERT_EQ(midpoint.outcome, TriangulationOutcome::kOk);
  EXPECT_EQ(midpoint.views.size(), 6u);
  EXPECT_LT((midpoint.xyz - X).norm(), 0.03);
  EXPECT_LT((midpoint.xyz - linear.xyz).norm(), 0.02);
  // Exact observations: the midpoint is the point itself.
  for (auto& v : views) observe(v, X, {0, 0});
  EXPECT_LT((triangulate_midpoint(views, {0, 5}) - X).norm(), 1e-9);
}

// A third of the views wrong: the refinement's pair order tries first and last, then inwards, so a pair of
// right views is among its 12 tries whichever views are wrong, and the consensus drops the wrong ones.
TEST(FrontendTriangulation, MidpointConsensusDropsAThirdOfWrongViews) {
  const Eigen::Vector3d X(0, 0.5, 8);
  std::vector<TriangulationView> views;
  for (int i = 0; i < 9; ++i) {
    views.push_back(look_at(Eigen::Vector3d(-2 + 0.5 * i, 0, 0), X));
    observe(views.back(), X, {0, 0});
  }
  for (size_t wrong : {0u, 4u, 8u}) views[wrong].xy += Eigen::Vector2d(40, 25) / kF;
  const TriangulatedPoint p = triangulate(views, kF, kF, TriangulationOptions::refinement());
  ASSERT_EQ(p.outcome, TriangulationOutcome::kOk);
  EXPECT_EQ(p.views, (std::vector<size_t>{1, 2, 3, 5, 6, 7}));
  EXPECT_LT((p.xyz - X).norm(), 1e-6);
}

// A Gaussian blob centred between pixels: the detector's keypoint sits on it (pixel centres at integer
// coordinates, the scene camera's convention) within a tenth of a pixel.
TEST(FrontendFeatures, SiftKeypointsSitOnTheFeature) {
  for (const FeatureType type : {FeatureType::kSift}) {
    for (const auto& [cx, cy] : {std::pair{40.3, 30.7}, std::pair{52.5, 41.0}, std::pair{61.0, 35.25}}) {
      Gray8 image;
      image.width = 100;
      image.height = 80;
      for (int y = 0; y < image.height; ++y)
        for (int x = 0; x < image.width; ++x) {
          const double r2 = (x - cx) * (x - cx) + (y - cy) * (y - cy);
          image.pixels.push_back(
              static_cast<uint8_t>(std::lround(30 + 200 * std::exp(-r2 / (2 * 4.0 * 4.0)))));
        }
      FeatureOptions o;
      o.type = type;
      o.grid_cols = o.grid_rows = 0;
      const ImageFeatures f = detect_features(image, o);
      ASSERT_FALSE(f.keypoints.empty()) << feature_name(type);
      double best = 1e9, dx = 0, dy = 0;
      for (const auto& k : f.keypoints) {
        const double d = std::hypot(k.x - cx, k.y - cy);
        if (d < best) {
          best = d;
          dx = k.x - cx;
          dy = k.y - cy;
        }
      }
      EXPECT_LT(std::abs(dx), 0.1) << feature_name(type) << " at " << cx << ", " << cy;
      EXPECT_LT(std::abs(dy), 0.1) << feature_name(type) << " at " << cx << ", " << cy;
    }
  }
}

TEST(FrontendTracks, UnionFindJoinsChainsAndRefusesTwoKeypointsOfOneImage) {
  // Image 0 kp 0 - image 1 kp 0 - image 2 kp 0: one track of three. Then image 2 kp 1 - image 0 kp 0 would
  // put two keypoints of image 2 in that track: a conflict, dropped. Image 1 kp 1 - image 2 kp 1: a second
  // track. An outlier match (inlier false) is ignored.
  std::vector<io::SfmPairMatches> pairs = {
      {0, 1, {{0, 0, true}, {1, 2, false}}},
      {1, 2, {{0, 0, true}, {1, 1, true}}},
      {0, 2, {{0, 1, true}}},
  };
  const TrackSet t = build_tracks({2, 3, 2}, pairs);
  EXPECT_EQ(t.conflicts, 1u);
  ASSERT_EQ(t.tracks.size(), 2u);
  EXPECT_EQ(t.tracks[0].observations, (std::vector<io::SfmObservation>{{0, 0}, {1, 0}, {2, 0}}));
  EXPECT_EQ(t.tracks[1].observations, (std::vector<io::SfmObservation>{{1, 1}, {2, 1}}));
  EXPECT_THROW(build_tracks({1, 1}, {{0, 1, {{0, 5, true}}}}), std::invalid_argument);
}

TEST(FrontendTracks, KeypointsAtOneLocationAreOneObservation) {
  // Image 1 has two keypoints at the same place (two SIFT orientations); image 0's keypoint matches one,
  // image 2's the other: one track of three, no conflict.
  const std::vector<std::vector<io::SfmKeypoint>> keypoints = {
      {{5, 5, 2, 0}}, {{7, 3, 2, 10}, {7, 3, 2, 200}}, {{1, 1, 2, 0}}};
  const auto representatives = same_location_representatives(keypoints);
  EXPECT_EQ(representatives[1], (std::vector<uint32_t>{0, 0}));
  const std::vector<io::SfmPairMatches> pairs = {{0, 1, {{0, 0, true}}}, {1, 2, {{1, 0, true}}}};
  EXPECT_EQ(build_tracks({1, 2, 1}, pairs).tracks.size(), 2u);  // without: two tracks of two
  const TrackSet t = build_tracks({1, 2, 1}, pairs, representatives);
  EXPECT_EQ(t.conflicts, 0u);
  ASSERT_EQ(t.tracks.size(), 1u);
  EXPECT_EQ(t.tracks[0].observations, (std::vector<io::SfmObservation>{{0, 0}, {1, 0}, {2, 0}}));
}

TEST(FrontendFeatures, GridBucketingSpreadsTheBudget) {
  // 100 strong keypoints in the top-left corner, 100 weak ones spread over the image.
  std::vector<float> x, y, r;
  for (int i = 0; i < 100; ++i) {
    x.push_back(static_cast<float>(i % 10));
    y.push_back(static_cast<float>(i / 10));
    r.push_back(100.0f + static_cast<float>(i));
  }
  for (int i = 0; i < 100; ++i) {
    x.push_back(static_cast<float>((i % 10) * 10 + 5));
    y.push_back(static_cast<float>((i / 10) * 10 + 5));
    r.push_back(1.0f);
  }
  const auto strongest = bucket_keypoints(x, y, r, 100, 100, 50, 0, 0);
  ASSERT_EQ(strongest.size(), 50u);
  for (size_t i : strongest) EXPECT_LT(i, 100u);
  const auto spread = bucket_keypoints(x, y, r, 100, 100, 50, 5, 5);  // 25 cells, quota 2
  ASSERT_EQ(spread.size(), 50u);
  size_t outside_corner = 0;
  for (size_t i : spread) outside_corner += x[i] >= 20 || y[i] >= 20;
  EXPECT_GE(outside_corner, 24u * 2 - 8);  // the 24 other cells get their quota (minus the corner's share)
}

TEST(FrontendFeatures, SpacingDropsAKeypointNearAStrongerOneButNotTheOrientationsOfOne) {
  //                          0      1      2      3      4      5      6
  const std::vector<float> x = {10.0f, 11.0f, 10.0f, 13.0f, 19.9f, 20.1f, 30.0f};
  const std::vector<float> y = {10.0f, 10.0f, 10.0f, 10.0f, 0.0f, 0.0f, 30.0f};
  const std::vector<float> r = {5.0f, 3.0f, 1.0f, 4.0f, 2.0f, 2.0f, 0.5f};
  // 1 lies 1 px from the stronger 0; 2 shares 0's position (another orientation); 3 is 3 px from 0 and
  // 2 px from 1, which is dropped and so spares it; 5 ties with 4 (the lower index is the stronger) across
  // a cell border of the search.
  EXPECT_EQ(spaced_keypoints(x, y, r, 2.5), (std::vector<size_t>{0, 2, 3, 4, 6}));
  EXPECT_EQ(spaced_keypoints(x, y, r, 0.5), (std::vector<size_t>{0, 1, 2, 3, 4, 6}));  // 5 is 0.2 px from 4
  EXPECT_EQ(spaced_keypoints(x, y, r, 0).size(), x.size());
  // Against every pair tested, on 600 random keypoints.
  std::mt19937 rng(7);
  std::uniform_real_distribution<float> u(0, 60);
  std::vector<float> rx, ry, rr;
  for (int i = 0; i < 600; ++i) {
    rx.push_back(u(rng));
    ry.push_back(u(rng));
    rr.push_back(u(rng));
  }
  std::vector<size_t> order(rx.size()), expected;
  std::iota(order.begin(), order.end(), size_t{0});
  std::stable_sort(order.begin(), order.end(), [&](size_t a, size_t b) { return rr[a] > rr[b]; });
  for (size_t i : order) {
    bool near = false;
    for (size_t j : expected) near = near || std::hypot(rx[i] - rx[j], ry[i] - ry[j]) < 3.0;
    if (!near) expected.push_back(i);
  }
  std::sort(expected.begin(), expected.end());
  EXPECT_EQ(spaced_keypoints(rx, ry, rr, 3.0), expected);
  FeatureOptions bad;
  bad.min_spacing_px = -1;
  EXPECT_THROW(bad.check(), std::invalid_argument);
}

TEST(FrontendIntensity, PercentileStretchAndConstantImages) {
  Histogram h = empty_histogram();
  for (uint16_t v = 1000; v < 2000; ++v) h[v] = 1;
  const Stretch s = percentile_stretch(h, 10, 90);
  EXPECT_DOUBLE_EQ(s.low, 1099);
  EXPECT_DOUBLE_EQ(s.high, 1899);
  Histogram constant = empty_histogram();
  constant[3500] = 640 * 512;
  const Stretch c = percentile_stretch(constant, 0.5, 99.5);
  EXPECT_DOUBLE_EQ(c.low, 3500);
  EXPECT_DOUBLE_EQ(c.high, 3501);
  EXPECT_EQ(c.unit(3500), 0.0f);
  EXPECT_THROW(percentile_stretch(empty_histogram(), 1, 99), std::invalid_argument);
  // A sliding window follows a drifting level: frame i is the constant 1000 + 100 i.
  std::vector<Histogram> frames(5, empty_histogram());
  for (size_t i = 0; i < 5; ++i) frames[i][1000 + 100 * i] = 10;
  const auto windowed = sequence_stretch(frames, 0, 100, 1);
  for (size_t i = 0; i < 5; ++i) EXPECT_DOUBLE_EQ(windowed[i].low, 1000.0 + 100.0 * static_cast<double>(i));
  const auto shared = sequence_stretch(frames, 0, 100, 0);
  for (size_t i = 0; i < 5; ++i) EXPECT_DOUBLE_EQ(shared[i].low, 1000.0);
}

TEST(FrontendFrozen, NearDuplicatesOfTheLastKeptFrameAreFrozen) {
  FrozenFrameDetector d(1e-3);
  std::vector<float> a(100, 0.5f), b(100, 0.5f), c(100, 0.6f);
  b[3] = 0.55f;  // mean difference 5e-4: frozen
  EXPECT_FALSE(d.is_frozen(a));
  EXPECT_TRUE(d.is_frozen(b));
  EXPECT_TRUE(d.is_frozen(a));
  EXPECT_FALSE(d.is_frozen(c));
  EXPECT_TRUE(d.is_frozen(c));
}

TEST(FrontendVerification, AllOutlierMatchesVerifyNothing) {
  std::mt19937 rng(3);
  std::uniform_real_distribution<double> u(0, 640), v(0, 512);
  std::vector<Eigen::Vector2d> a, b;
  std::vector<std::array<uint32_t, 2>> matches;
  for (uint32_t i = 0; i < 400; ++i) {
    a.emplace_back(u(rng), v(rng));
    b.emplace_back(u(rng), v(rng));
    matches.push_back({i, i});
  }
  const PinholeK K{600, 600, 320, 256};
  const Verification without_prior = verify_pair(a, b, matches, K, std::nullopt, {});
  EXPECT_FALSE(without_prior.verified);
  EXPECT_EQ(without_prior.inliers, 0u);
  for (uint8_t f : without_prior.inlier) EXPECT_EQ(f, 0);
  RelativePose prior;
  prior.t_ba = {1, 0, 0};
  const Verification with_prior = verify_pair(a, b, matches, K, prior, {});
  EXPECT_FALSE(with_prior.verified);
  EXPECT_GT(with_prior.rejected_by_prior, 300u);  // a random point lies within 8 px of a line rarely
}

TEST(FrontendVerification, PriorDistanceIsZeroOnTheEpipolarLine) {
  const PinholeK K{600, 600, 320, 256};
  RelativePose prior;
  prior.R_ba = Eigen::AngleAxisd(0.1, Eigen::Vector3d::UnitY()).toRotationMatrix();
  prior.t_ba = {-1, 0.1, 0};
  const Eigen::Vector3d X(0.4, -0.3, 6);
  const Eigen::Vector3d xb = prior.R_ba * X + prior.t_ba;
  const Eigen::Vector2d pa(K.fx * X.x() / X.z() + K.cx, K.fy * X.y() / X.z() + K.cy);
  const Eigen::Vector2d pb(K.fx * xb.x() / xb.z() + K.cx, K.fy * xb.y() / xb.z() + K.cy);
  EXPECT_LT(prior_distance_px(pa, pb, K, prior), 1e-9);
  EXPECT_GT(prior_distance_px(pa, pb + Eigen::Vector2d(0, 10), K, prior), 5);
}

TEST(FrontendVerification, PriorCandidatesAreExactlyThoseWithinTheBound) {
  // The bucketed search must find what testing every pair finds, for flat and steep epipolar lines and
  // keypoints outside the image (undistortion can push them there).
  std::mt19937 rng(11);
  std::uniform_real_distribution<double> u(-20, 660), v(-20, 530);
  const PinholeK K{600, 610, 320, 256};
  for (const Eigen::Vector3d& t : {Eigen::Vector3d(1, 0.1, 0.05), Eigen::Vector3d(0.05, 1, 0.2),
                                   Eigen::Vector3d(0.2, -0.1, 1), Eigen::Vector3d(0, 0, 0)}) {
    RelativePose prior;
    prior.R_ba = Eigen::AngleAxisd(0.05, Eigen::Vector3d(0.3, 1, 0.2).normalized()).toRotationMatrix();
    prior.t_ba = t;
    std::vector<Eigen::Vector2d> a, b;
    for (int i = 0; i < 600; ++i) {
      a.emplace_back(u(rng), v(rng));
      b.emplace_back(u(rng), v(rng));
    }
    const auto found = prior_candidates(a, b, K, prior, 8);
    size_t total = 0;
    for (size_t i = 0; i < a.size(); ++i) {
      std::vector<uint32_t> expected;
      for (uint32_t j = 0; j < b.size(); ++j)
        if (prior_distance_px(a[i], b[j], K, prior) <= 8) expected.push_back(j);
      std::vector<uint32_t> got = found[i];
      std::sort(got.begin(), got.end());
      EXPECT_EQ(got, expected) << "keypoint " << i << " t " << t.transpose();
      total += expected.size();
    }
    EXPECT_GT(total, 100u);  // the bound is met often enough for the comparison to mean something
  }
}

TEST(FrontendPairs, SelectionModes) {
  EXPECT_EQ(sequential_pairs({0, 2, 3, 5}, 2),
            (std::vector<ImagePair>{{0, 2}, {0, 3}, {2, 3}, {2, 5}, {3, 5}}));
  EXPECT_EQ(exhaustive_pairs({1, 2, 3}).size(), 3u);
  EXPECT_EQ(parse_pairs("sequential:4").window, 4u);
  EXPECT_EQ(parse_pairs("exhaustive").mode, PairMode::kExhaustive);
  EXPECT_THROW(parse_pairs("sequential:x"), std::invalid_argument);
  EXPECT_THROW(parse_pairs("all"), std::invalid_argument);
  // Three views of a wall 5 m away: two side by side overlap, one turned away does not.
  std::vector<PairView> views(3);
  for (int i = 0; i < 3; ++i) {
    views[i].valid = true;
    views[i].depth_m = 5;
    views[i].t_cam_world = Eigen::Vector3d(-0.5 * i, 0, 0);
  }
  views[2].R_cam_world = Eigen::AngleAxisd(M_PI, Eigen::Vector3d::UnitY()).toRotationMatrix();
  const auto pairs = covisible_pairs({0, 1, 2}, views, 300, 300, 160, 120, 320, 240, {});
  EXPECT_EQ(pairs, (std::vector<ImagePair>{{0, 1}}));
}

}  // namespace
}  // namespace litgs::host::frontend
