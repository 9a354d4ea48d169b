// The exact assignment solver against brute force over all permutations, and EMD on sets whose answer is
// known in closed form.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <limits>
#include <numeric>
#include <random>

#include "host/eval/assignment.h"
#include "host/eval/emd.h"

namespace litgs::host {
namespace {

double brute_force_min_cost(const std::vector<double>& cost, size_t n) {
  std::vector<size_t> perm(n);
  std::iota(perm.begin(), perm.end(), size_t{0});
  double best = std::numeric_limits<double>::infinity();
  do {
    double c = 0;
    for (size_t i = 0; i < n; ++i) c += cost[i * n + perm[i]];
    best = std::min(best, c);
  } while (std::next_permutation(perm.begin(), perm.end()));
  return best;
}

TEST(Assignment, MatchesBruteForceOnRandomMatrices) {
  std::mt19937 rng(7);
  for (size_t n = 1; n <= 8; ++n)
    for (int trial = 0; trial < 25; ++trial) {
      // Mixed signs, and ties (integers) in half of the trials: the degenerate case of the simplex.
      std::uniform_real_distribution<double> real(-5, 10);
      std::uniform_int_distribution<int> integer(0, 3);
      std::vector<double> cost(n * n);
      for (double& c : cost) c = trial % 2 ? real(rng) : integer(rng);
      const Assignment a = min_cost_assignment(n, [&](size_t i, size_t j) { return cost[i * n + j]; });
      std::vector<size_t> sorted = a.column_of_row;
      std::sort(sorted.begin(), sorted.end());
      for (size_t k = 0; k < n; ++k) ASSERT_EQ(sorted[k], k) << "not a permutation, n " << n;
      double check = 0;
      for (size_t i = 0; i < n; ++i) check += cost[i * n + a.column_of_row[i]];
      EXPECT_NEAR(a.total_cost, check, 1e-12);
      EXPECT_NEAR(a.total_cost, brute_force_min_cost(cost, n), 1e-9) << "n " << n << " trial " << trial;
    }
}

TEST(Assignment, EmptyAndNonFinite) {
  EXPECT_EQ(min_cost_assignment(0, [](size_t, size_t) { return 1.0; }).total_cost, 0.0);
  try {
    min_cost_assignment(3, [](size_t i, size_t j) { return i == 1 && j == 2 ? NAN : 1.0; });
    FAIL() << "a NaN cost was accepted";
  } catch (const std::invalid_argument& e) {
    EXPECT_NE(std::string(e.what()).find("cost(1, 2)"), std::string::npos) << e.what();
  }
}

TEST(Emd, PointSetsAgainstBruteForce) {
  std::mt19937 rng(3);
  std::normal_distribution<double> g(0, 1);
  for (size_t n = 1; n <= 7; ++n) {
    std::vector<Eigen::Vector3d> a(n), b(n);
    for (auto& p : a) p = {g(rng), g(rng), g(rng)};
    for (auto& p : b) p = {g(rng) + 0.5, g(rng), g(rng)};
    std::vector<double> cost(n * n);
    for (size_t i = 0; i < n; ++i)
      for (size_t j = 0; j < n; ++j) cost[i * n + j] = (a[i] - b[j]).norm();
    EXPECT_NEAR(earth_movers_distance(a, b), brute_force_min_cost(cost, n) / static_cast<double>(n), 1e-12);
  }
}

TEST(Emd, ClosedFormCases) {
  // A set against itself shuffled: 0. Against itself translated by t: |t| (a translation is optimal for the
  // convex cost |x - y|: every matched pair moves by t, and no matching can do better on average, since
  // (1/n) sum |a_i - b_s(i)| >= |mean(a) - mean(b)| = |t|).
  std::mt19937 rng(11);
  std::uniform_real_distribution<double> u(-3, 3);
  std::vector<Eigen::Vector3d> a(300);
  for (auto& p : a) p = {u(rng), u(rng), u(rng)};
  std::vector<Eigen::Vector3d> shuffled = a;
  std::shuffle(shuffled.begin(), shuffled.end(), rng);
  EXPECT_NEAR(earth_movers_distance(a, shuffled), 0.0, 1e-12);
  const Eigen::Vector3d t(0.3, -0.4, 1.2);
  std::vector<Eigen::Vector3d> moved = shuffled;
  for (auto& p : moved) p += t;
  EXPECT_NEAR(earth_movers_distance(a, moved), t.norm(), 1e-9);
  EXPECT_THROW(earth_movers_distance(a, std::vector<Eigen::Vector3d>(2)), std::invalid_argument);
}

TEST(Emd, SamplingFollowsTheWeightsAndTheSeed) {
  const std::vector<Eigen::Vector3d> pts = {{0, 0, 0}, {1, 0, 0}, {2, 0, 0}};
  const std::vector<double> w = {0.0, 1.0, 3.0};
  const auto s = sample_by_weight(pts, w, 40000, 5);
  size_t ones = 0, twos = 0;
  for (const auto& p : s) {
    ASSERT_NE(p.x(), 0.0) << "a zero-weight point was drawn";
    (p.x() == 1.0 ? ones : twos)++;
  }
  EXPECT_NEAR(static_cast<double>(twos) / static_cast<double>(s.size()), 0.75, 0.01);
  EXPECT_EQ(sample_by_weight(pts, w, 100, 5), sample_by_weight(pts, w, 100, 5));
  EXPECT_NE(sample_by_weight(pts, w, 100, 5), sample_by_weight(pts, w, 100, 6));
  EXPECT_THROW(sample_by_weight(pts, {0, 0, 0}, 1, 0), std::invalid_argument);
  EXPECT_THROW(sample_by_weight(pts, {1, -1, 0}, 1, 0), std::invalid_argument);

  const auto distinct = sample_uniform(pts, 10, 1);
  ASSERT_EQ(distinct.size(), 3u);  // at most the set, no repeats
  EXPECT_NE(distinct[0], distinct[1]);
  EXPECT_NE(distinct[1], distinct[2]);
  EXPECT_NE(distinct[0], distinct[2]);
}

TEST(Emd, GaussianEmdOfAPerfectModelIsSmall) {
  // Centres = the reference cloud (equal opacities): the EMD is the matching distance between two random
  // subsets of one cloud, which shrinks like L sqrt(log n / n) (Ajtai-Komlos-Tusnady; about 0.5 m here for
  // n = 400 in a 10 m square): well below a tenth of the cloud's size. Lifting the centres by 1 m out of the
  // cloud's plane (same seeds, so the same draws) makes every matched distance at least 1 m, and at most
  // sqrt(d^2 + 1) <= d + 1 for the unlifted optimum's distances d.
  std::mt19937 rng(2);
  std::uniform_real_distribution<double> u(0, 10);
  std::vector<Eigen::Vector3d> cloud(5000);
  for (auto& p : cloud) p = {u(rng), u(rng), 0.0};
  EmdOptions o;
  o.samples = 400;
  o.rounds = 2;
  const EmdResult same = gaussian_emd(cloud, std::vector<double>(cloud.size(), 0.5), cloud, o);
  EXPECT_EQ(same.samples, 400u);
  EXPECT_LT(same.mean_m, 1.0);
  // The floor is the same measure between two draws of the reference: here the model is the reference.
  EXPECT_NEAR(same.mean_m, same.floor_m, 0.25 * same.floor_m);
  std::vector<Eigen::Vector3d> lifted = cloud;
  for (auto& p : lifted) p.z() += 1.0;
  const EmdResult off = gaussian_emd(lifted, std::vector<double>(cloud.size(), 0.5), cloud, o);
  EXPECT_GE(off.mean_m, 1.0);
  EXPECT_LE(off.mean_m, 1.0 + same.mean_m + 1e-9);
}

}  // namespace
}  // namespace litgs::host

namespace litgs::host {
namespace {

TEST(Emd, UniformDrawsIgnoreOpacity) {
  // Two clusters 10 m apart with the reference split evenly; all opacity on the first cluster. Weighted draws
  // take only the first cluster, so half the mass must travel about 10 m (EMD near 5 m); uniform draws match
  // the reference's split (EMD near the floor).
  std::vector<Eigen::Vector3d> pts;
  std::vector<double> opacity;
  for (int i = 0; i < 200; ++i) {
    pts.push_back({0.01 * i, 0, 0});
    opacity.push_back(1.0);
  }
  for (int i = 0; i < 200; ++i) {
    pts.push_back({10 + 0.01 * i, 0, 0});
    opacity.push_back(0.0);
  }
  EmdOptions o;
  o.samples = 100;
  o.rounds = 1;
  const EmdResult weighted = gaussian_emd(pts, opacity, pts, o);
  o.weight_by_opacity = false;
  const EmdResult uniform = gaussian_emd(pts, opacity, pts, o);
  EXPECT_FALSE(uniform.weighted_by_opacity);
  EXPECT_GT(weighted.mean_m, 3.0);
  EXPECT_LT(uniform.mean_m, 1.0);
}

}  // namespace
}  // namespace litgs::host
