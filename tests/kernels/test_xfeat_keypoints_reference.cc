// XFeat's post-processing in double precision (kernels/nn/xfeat_keypoints_reference.h) on cases worked by
// hand: the softmax's cell layout, NMS and the threshold, XFeat's sampling positions, the top-k order, the
// bicubic descriptor sampling against Keys' kernel written out independently, and a uniform image.
#include <gtest/gtest.h>

#include <cmath>

#include "kernels/nn/xfeat_keypoints_reference.h"

namespace litgs::kernels::nn {
namespace {

TEST(XfeatKeypointsReference, SoftmaxPutsEachBinAtItsPixelOfTheCell) {
  FeatureMap logits(65, 2, 3);            // all zero logits but one
  logits.at(19, 1, 2) = std::log(100.0);  // bin 19: row 2, column 3 of cell (1, 2)
  const FeatureMap heat = keypoint_heatmap(logits);
  ASSERT_EQ(heat.height, 16);
  ASSERT_EQ(heat.width, 24);
  EXPECT_NEAR(heat.at(0, 8 + 2, 16 + 3), 100.0 / 164.0, 1e-12);
  EXPECT_NEAR(heat.at(0, 8, 16), 1.0 / 164.0, 1e-12);
  EXPECT_NEAR(heat.at(0, 0, 0), 1.0 / 65.0, 1e-12);  // a cell of equal logits
  double cell = 0;
  for (int y = 8; y < 16; ++y)
    for (int x = 16; x < 24; ++x) cell += heat.at(0, y, x);
  EXPECT_NEAR(cell + 1.0 / 164.0, 1.0, 1e-12);  // with the "no keypoint" bin the cell sums to one
  EXPECT_THROW(keypoint_heatmap(FeatureMap(64, 2, 2)), std::invalid_argument);
}

TEST(XfeatKeypointsReference, NmsKeepsWindowMaximaAboveTheThresholdTimesReliability) {
  FeatureMap heat(1, 32, 32), reliability(1, 4, 4);
  for (double& r : reliability.values) r = 0.5;
  heat.at(0, 10, 10) = 0.5;
  heat.at(0, 10, 12) = 0.4;  // 2 px from a larger one: suppressed
  heat.at(0, 20, 10) = 0.3;
  heat.at(0, 20, 13) = 0.3;  // 3 px apart: outside each other's window
  heat.at(0, 26, 20) = 0.2;
  heat.at(0, 26, 21) = 0.2;   // a tie within one window: both are its maximum, both kept
  heat.at(0, 16, 24) = 0.04;  // below the threshold
  const FeatureMap s = keypoint_scores(heat, reliability, {});
  int kept = 0;
  for (double v : s.values) kept += v > 0;
  EXPECT_EQ(kept, 5);
  EXPECT_NEAR(s.at(0, 10, 10), 0.25, 1e-12);
  EXPECT_EQ(s.at(0, 10, 12), 0.0);
  EXPECT_NEAR(s.at(0, 20, 13), 0.15, 1e-12);
  EXPECT_EQ(s.at(0, 16, 24), 0.0);
}

TEST(XfeatKeypointsReference, MapsAreSampledWhereXfeatSamplesThem) {
  // A ramp r = column of the 1/8 map: at full-resolution x the sample is x * w / (W - 1) - 0.5.
  FeatureMap ramp(1, 4, 6);
  for (int y = 0; y < 4; ++y)
    for (int x = 0; x < 6; ++x) ramp.at(0, y, x) = x;
  for (double x : {5.0, 17.0, 30.0})
    EXPECT_NEAR(sample_bilinear(ramp, 0, x, 16, 48, 32), x * 6 / 47.0 - 0.5, 1e-12) << x;
  FeatureMap ones(1, 4, 6);
  for (double& v : ones.values) v = 1;
  EXPECT_NEAR(sample_bilinear(ones, 0, 0, 0, 48, 32), 0.25, 1e-12);  // zero outside the map
}

TEST(XfeatKeypointsReference, TopKIsByScoreThenRowMajor) {
  std::vector<float> s(4 * 3, 0.0f);
  s[1] = 0.2f;
  s[4] = 0.9f;
  s[7] = 0.2f;
  s[10] = 0.5f;
  const auto all = top_keypoints(s, 4, 3, 10);
  ASSERT_EQ(all.size(), 4u);
  EXPECT_EQ(all[0].x, 0);
  EXPECT_EQ(all[0].y, 1);
  EXPECT_EQ(all[1].x, 2);
  EXPECT_EQ(all[1].y, 2);
  EXPECT_EQ(all[2].x, 1);  // the tie: index 1 before index 7
  EXPECT_EQ(all[2].y, 0);
  EXPECT_EQ(all[3].x, 3);
  EXPECT_EQ(top_keypoints(s, 4, 3, 2).size(), 2u);
  EXPECT_THROW(top_keypoints(s, 5, 3, 2), std::invalid_argument);
}

// Keys' cubic convolution kernel with a = -0.75, written out by its cases.
double keys(double d) {
  const double a = -0.75, t = std::abs(d);
  if (t <= 1) return (a + 2) * t * t * t - (a + 3) * t * t + 1;
  if (t < 2) return a * t * t * t - 5 * a * t * t + 8 * a * t - 4 * a;
  return 0;
}

TEST(XfeatKeypointsReference, DescriptorsAreBicubicThenUnitLength) {
  // Two channels, each a single tap: the sample is the kernel's product at the offsets.
  FeatureMap m(2, 6, 8);
  m.at(0, 3, 4) = 1;
  m.at(1, 2, 3) = 1;
  const int W = 64, H = 48;
  const ScoredKeypoint k{29.3f, 21.7f, 1};
  const double u = k.x * 8.0 / (W - 1) - 0.5, v = k.y * 6.0 / (H - 1) - 0.5;
  const double a = keys(u - 4) * keys(v - 3), b = keys(u - 3) * keys(v - 2);
  const std::vector<double> d = sample_descriptors(m, {k}, W, H);
  ASSERT_EQ(d.size(), 2u);
  EXPECT_NEAR(d[0], a / std::hypot(a, b), 1e-12);
  EXPECT_NEAR(d[1], b / std::hypot(a, b), 1e-12);
  // normalize_channels: each cell's channels to unit length, an all-zero cell stays zero.
  FeatureMap f(2, 1, 2);
  f.at(0, 0, 0) = 3;
  f.at(1, 0, 0) = 4;
  const FeatureMap n = normalize_channels(f);
  EXPECT_NEAR(n.at(0, 0, 0), 0.6, 1e-15);
  EXPECT_NEAR(n.at(1, 0, 0), 0.8, 1e-15);
  EXPECT_EQ(n.at(0, 0, 1), 0.0);
}

TEST(XfeatKeypointsReferenceHardCases, UniformLogitsGiveNoKeypointsAndNoNaN) {
  FeatureMap features(64, 4, 4), logits(65, 4, 4), reliability(1, 4, 4);
  for (double& r : reliability.values) r = 1;
  const XfeatKeypoints k = detect_keypoints(features, logits, reliability, {});
  EXPECT_TRUE(k.keypoints.empty());  // every heat is 1/65, below 0.05
  EXPECT_TRUE(k.descriptors.empty());
}

}  // namespace
}  // namespace litgs::kernels::nn
