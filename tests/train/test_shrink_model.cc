// keep_most_opaque (host/train/shrink_model.h): a budget growth's roll-back keeps the most opaque rows, in
// their order, each with its own moments and statistics.
#include <gtest/gtest.h>

#include "host/train/shrink_model.h"

namespace litgs::host {
namespace {

// Five rows whose every value names its row (row r holds r, 10 + r, ...), opacity logits as given.
kernels::TrainingState numbered_state(const std::vector<float>& opacity) {
  kernels::GaussianModel m;
  m.channels = 1;
  m.sh_degree = 0;
  m.resize(opacity.size());
  for (size_t r = 0; r < opacity.size(); ++r) {
    for (int k = 0; k < 3; ++k) m.means[3 * r + k] = static_cast<float>(r);
    m.opacity_logits[r] = opacity[r];
    m.sh[r] = 100.0f + static_cast<float>(r);
  }
  kernels::TrainingState s = kernels::TrainingState::fresh(m);
  for (size_t r = 0; r < opacity.size(); ++r) {
    s.exp_avg[kernels::kMeans][3 * r] = 1000.0f + static_cast<float>(r);
    s.exp_avg_sq[kernels::kSh][r] = 2000.0f + static_cast<float>(r);
    s.denom[r] = static_cast<uint32_t>(r);
  }
  return s;
}

TEST(ShrinkModel, KeepsTheMostOpaqueRowsInTheirOrderWithTheirMoments) {
  const kernels::TrainingState s = numbered_state({0.1f, 2.0f, -1.0f, 2.0f, 0.5f});
  const kernels::TrainingState k = keep_most_opaque(s, 3);
  ASSERT_EQ(k.size(), 3u);
  EXPECT_EQ(k.model.opacity_logits, (std::vector<float>{2.0f, 2.0f, 0.5f}));  // rows 1, 3, 4
  EXPECT_EQ(k.model.means[3], 3.0f);
  EXPECT_EQ(k.model.sh, (std::vector<float>{101.0f, 103.0f, 104.0f}));
  EXPECT_EQ(k.exp_avg[kernels::kMeans][6], 1004.0f);
  EXPECT_EQ(k.exp_avg_sq[kernels::kSh], (std::vector<float>{2001.0f, 2003.0f, 2004.0f}));
  EXPECT_EQ(k.denom, (std::vector<uint32_t>{1, 3, 4}));
  EXPECT_EQ(k.max_radius.size(), 3u);
}

TEST(ShrinkModel, ASmallerModelIsLeftAsItIsAndTiesKeepTheLowerRow) {
  const kernels::TrainingState s = numbered_state({1.0f, 1.0f, 1.0f});
  EXPECT_EQ(keep_most_opaque(s, 5).model.sh, s.model.sh);
  EXPECT_EQ(keep_most_opaque(s, 2).model.sh, (std::vector<float>{100.0f, 101.0f}));
  kernels::TrainingState bad = s;
  bad.denom.pop_back();
  EXPECT_THROW(keep_most_opaque(bad, 2), std::invalid_argument);
}

}  // namespace
}  // namespace litgs::host
