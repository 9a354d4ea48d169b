// CPU tests of the level model's host side (host/train/level_plan.h) and of the generator's level drift
// (synth --drift, host/synth/level_drift.h): NUC segments and neighbours on a scene with a freeze, held-out
// levels interpolated in time, levels.json round trip and errors, and the drift applied to the raw frames
// exactly as gt/levels.txt states.
#include <gtest/gtest.h>
#include <unistd.h>

#include <cmath>
#include <filesystem>
#include <fstream>
#include <sstream>

#include "host/synth/synth.h"
#include "host/train/level_plan.h"
#include "host/train/training_data.h"
#include "io/error.h"
#include "io/scene.h"
#include "kernels/level/level_shared.h"

namespace litgs::host {
namespace {

namespace fs = std::filesystem;

class LevelPlanTest : public ::testing::Test {
 protected:
  static void SetUpTestSuite() {
    root_ = fs::temp_directory_path() / ("litgs-level-plan-" + std::to_string(::getpid()));
    fs::remove_all(root_);
    for (bool drift : {false, true}) {
      synth::SynthOptions s;
      s.frames = 12;
      s.width = 32;
      s.height = 24;
      s.drift = drift;
      s.out = root_ / (drift ? "drift" : "plain");
      synth::generate_synthetic_scene(s);
    }
    TrainingDataOptions d;
    d.holdout_every = 4;
    data_ = new TrainingData(load_training_data(root_ / "drift", d));
  }
  static void TearDownTestSuite() {
    delete data_;
    data_ = nullptr;
    fs::remove_all(root_);
  }
  static inline fs::path root_;
  static inline TrainingData* data_ = nullptr;
};

TEST_F(LevelPlanTest, FreezeStartsASegmentAndNeighboursStayInside) {
  // The facade preset freezes frames 8 and 9 of 12 at this seed (gt/frozen.txt): they are skipped, and the
  // next view starts a segment.
  ASSERT_EQ(data_->frozen_skipped, 2u);
  ASSERT_EQ(data_->views.size(), 10u);
  const LevelPlan plan(*data_);
  for (size_t i = 0; i < data_->views.size(); ++i) {
    EXPECT_EQ(data_->views[i].after_frozen, i == 8) << i;
    EXPECT_EQ(plan.segment[i], i >= 8 ? 1u : 0u) << i;
    for (int n : {plan.prev[i], plan.next[i]}) {
      if (n < 0) continue;
      EXPECT_FALSE(data_->views[static_cast<size_t>(n)].heldout);
      EXPECT_EQ(plan.segment[static_cast<size_t>(n)], plan.segment[i]);
    }
  }
  EXPECT_EQ(plan.prev[8], -1) << "no neighbour across the freeze";
  EXPECT_EQ(plan.next[7], -1) << "no neighbour across the freeze";
  EXPECT_EQ(plan.prev[2], 1);  // views 0 and 4 are held out
  EXPECT_EQ(plan.next[3], 5);
}

TEST_F(LevelPlanTest, HeldOutLevelsAreInterpolatedInTimeWithinTheirSegment) {
  const LevelPlan plan(*data_);
  std::vector<float> state((data_->views.size() + 1) * LEVEL_STRIDE, 0.0f);
  // Trained views: log-gain 0.1 t and offset -0.2 t (t from the first view), linear in time.
  const double t0 = data_->views[0].t_s;
  for (size_t i = 0; i < data_->views.size(); ++i) {
    const double t = data_->views[i].t_s - t0;
    state[i * LEVEL_STRIDE] = static_cast<float>(data_->views[i].heldout ? 99 : 0.1 * t);
    state[i * LEVEL_STRIDE + 1] = static_cast<float>(data_->views[i].heldout ? 99 : -0.2 * t);
  }
  const LevelTable table = make_level_table(*data_, plan, LevelModelKind::kAffine, state);
  for (size_t i = 0; i < data_->views.size(); ++i) {
    const double t = data_->views[i].t_s - t0;
    const LevelEntry& e = table.entries[i];
    if (i == 0) {  // held out before the first trained view: the nearest's level
      EXPECT_NEAR(e.log_gain, 0.1 * (data_->views[1].t_s - t0), 1e-6);
    } else {  // trained, or held out between two trained views of the segment (view 4): linear
      EXPECT_NEAR(e.log_gain, 0.1 * t, 1e-6) << i;
      EXPECT_NEAR(e.offset, -0.2 * t, 1e-6) << i;
    }
  }
  // By time: the segment of the nearest entry; at a trained view's time its own level.
  EXPECT_NEAR(table.at_time(data_->views[5].t_s).offset, table.entries[5].offset, 1e-9);
  const LevelTable none = make_level_table(*data_, plan, LevelModelKind::kNone, {});
  for (const auto& e : none.entries) EXPECT_EQ(e.log_gain == 0 && e.offset == 0, true);
}

TEST_F(LevelPlanTest, LevelsJsonRoundTripsAndBadFilesAreErrorsNamingThem) {
  const LevelPlan plan(*data_);
  std::vector<float> state((data_->views.size() + 1) * LEVEL_STRIDE, 0.0f);
  state[2 * LEVEL_STRIDE] = 0.25f;
  state[data_->views.size() * LEVEL_STRIDE] = -0.125f;  // k1
  const LevelTable t = make_level_table(*data_, plan, LevelModelKind::kAffineVignetting, state);
  write_level_table(root_ / "levels.json", t);
  const LevelTable r = read_level_table(root_ / "levels.json");
  EXPECT_EQ(r.model, "affine-vignetting");
  EXPECT_EQ(r.k1, -0.125);
  EXPECT_EQ(r.stretch_low, data_->stretch_low);
  ASSERT_EQ(r.entries.size(), t.entries.size());
  EXPECT_EQ(r.entries[2].log_gain, 0.25);
  EXPECT_EQ(r.values(2).k1, -0.125);
  std::ofstream(root_ / "bad.json") << R"({"level_model": "cubic"})";
  try {
    read_level_table(root_ / "bad.json");
    FAIL() << "accepted";
  } catch (const io::IoError& e) {
    EXPECT_NE(std::string(e.what()).find("bad.json"), std::string::npos) << e.what();
  }
  EXPECT_THROW(parse_level_model("cubic"), std::invalid_argument);
}

TEST_F(LevelPlanTest, DriftIsAppliedToTheRawFramesAsGroundTruthStates) {
  std::ifstream in(root_ / "drift" / "gt" / "levels.txt");
  std::string line;
  std::vector<std::array<double, 3>> rows;  // frame, gain, offset
  while (std::getline(in, line)) {
    if (line.empty() || line[0] == '#') continue;
    std::istringstream s(line);
    double t, f, g, o;
    s >> t >> f >> g >> o;
    rows.push_back({f, g, o});
  }
  ASSERT_EQ(rows.size(), 12u);
  EXPECT_EQ(rows[0][1], 1.0);
  EXPECT_EQ(rows[0][2], 0.0);
  EXPECT_NEAR(rows[11][1], 1.1, 1e-12);
  EXPECT_NEAR(rows[7][2], 200 * (1 - std::exp(-3.0 * 7 / 11)),
              1e-4);  // before the freeze (frame times: 0.1 s, as written)
  EXPECT_EQ(rows[8][2], rows[7][2]) << "a frozen frame repeats its source, level included";
  EXPECT_NEAR(rows[10][2], 200 * (1 - std::exp(-3.0 * 10 / 11)) - 150, 1e-4);  // the NUC jump
  io::SceneReadOptions read;
  const io::Scene plain = io::read_scene(root_ / "plain", read),
                  drift = io::read_scene(root_ / "drift", read);
  for (size_t i : {size_t{3}, size_t{10}}) {
    const io::Image a = io::load_frame(root_ / "plain", plain, i),
                    b = io::load_frame(root_ / "drift", drift, i);
    ASSERT_EQ(a.data.size(), b.data.size());
    for (size_t p = 0; p < a.data.size(); ++p)
      ASSERT_EQ(b.data[p], std::lround(rows[i][1] * a.data[p] + rows[i][2]))
          << "frame " << i << " pixel " << p;
  }
}

}  // namespace
}  // namespace litgs::host
