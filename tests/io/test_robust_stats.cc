// io/robust_stats.h on sets worked by hand.
#include <gtest/gtest.h>

#include <limits>
#include <vector>

#include "io/robust_stats.h"

namespace litgs::io {
namespace {

TEST(RobustStats, TheMedianIsTheUpperMiddleElementAndZeroForNone) {
  EXPECT_EQ(median({}), 0.0);
  EXPECT_EQ(median({7}), 7.0);
  EXPECT_EQ(median({3, 1, 2}), 2.0);
  EXPECT_EQ(median({4, 1, 3, 2}), 3.0);  // the upper of 2 and 3
}

TEST(RobustStats, QuantilesRoundTheirRankDownAndClampQ) {
  const std::vector<double> v = {50, 10, 40, 20, 30};
  EXPECT_EQ(quantile(v, 0), 10.0);
  EXPECT_EQ(quantile(v, 0.5), 30.0);
  EXPECT_EQ(quantile(v, 0.74), 30.0);  // rank 2.96 rounds down to 2
  EXPECT_EQ(quantile(v, 1), 50.0);
  EXPECT_EQ(quantile(v, 7), 50.0);
  EXPECT_EQ(quantile({}, 0.5), 0.0);
}

TEST(RobustStats, TheUpperBoundIsMedianPlusKScaledMadAtLeastTheFloor) {
  // median 3, absolute deviations {2, 1, 0, 1, 97}: MAD 1.
  const std::vector<double> v = {1, 2, 3, 4, 100};
  EXPECT_DOUBLE_EQ(robust_upper_bound(v, 3, 0), 3 + 3 * 1.4826);
  EXPECT_DOUBLE_EQ(robust_upper_bound(v, 3, 50), 50.0);
  // A constant set has no spread: the bound is the value itself, or the floor above it.
  EXPECT_DOUBLE_EQ(robust_upper_bound({5, 5, 5}, 3, 0), 5.0);
  EXPECT_DOUBLE_EQ(robust_upper_bound({5, 5, 5}, 3, 6), 6.0);
  EXPECT_DOUBLE_EQ(robust_upper_bound({}, 3, 0.25), 0.25);
  EXPECT_EQ(robust_upper_bound({}, 3, std::numeric_limits<double>::infinity()),
            std::numeric_limits<double>::infinity());
}

}  // namespace
}  // namespace litgs::io
