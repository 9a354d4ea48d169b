// The initialization policy of a training (host/train/initial_model.h): which source `--init auto` picks,
// the caps on a LiDAR-map seeding, and the errors that name what to run.
#include <gtest/gtest.h>

#include <filesystem>
#include <string>

#include "host/train/initial_model.h"
#include "io/sfm_files.h"

namespace litgs::host {
namespace {

namespace fs = std::filesystem;

class InitialModelTest : public ::testing::Test {
 protected:
  void SetUp() override {
    scene_ = fs::temp_directory_path() /
             ("litgs-initial-model-" +
              std::string(::testing::UnitTest::GetInstance()->current_test_info()->name()));
    fs::remove_all(scene_);
    fs::create_directories(scene_);
  }
  void TearDown() override { fs::remove_all(scene_); }

  // SCENE/sfm/ with `n` triangulated points, as `match` writes it.
  void write_front_end_points(size_t n) {
    io::SfmData sfm;
    sfm.images.push_back({"thermal/0.png", false, {{1, 2, 1, 0}, {3, 4, 1, 0}}});
    sfm.images.push_back({"thermal/1.png", false, {{1, 2, 1, 0}, {3, 4, 1, 0}}});
    for (size_t i = 0; i < n; ++i)
      sfm.points.push_back({Eigen::Vector3d(0.1 * static_cast<double>(i), 0, 5), 0.5, {{0, 0}, {1, 0}}});
    io::write_sfm(scene_ / "sfm", sfm, "{}");
  }

  // A map of `n` points on the plane z = 5, every one fitted as planar with normal +z.
  static std::vector<Eigen::Vector3d> wall(size_t n, PlanarMap& planes) {
    std::vector<Eigen::Vector3d> points;
    for (size_t i = 0; i < n; ++i) {
      points.emplace_back(0.05 * static_cast<double>(i % 10), 0.05 * static_cast<double>(i / 10), 5);
      planes.points.push_back(points.back().cast<float>());
      planes.normals.emplace_back(0, 0, 1);
      planes.centres.push_back(points.back().cast<float>());
      planes.planar.push_back(1);
      planes.flatness.push_back(0);
    }
    return points;
  }

  fs::path scene_;
};

TEST_F(InitialModelTest, AutoTakesTheMapThenTheFrontEndsPointsThenRandom) {
  PlanarMap planes;
  const std::vector<Eigen::Vector3d> map = wall(20, planes), no_map;
  EXPECT_EQ(InitialModel({}, scene_, map, false).source(), InitialSource::kMap);
  EXPECT_EQ(InitialModel({}, scene_, no_map, false).source(), InitialSource::kRandom);
  write_front_end_points(3);
  EXPECT_EQ(InitialModel({}, scene_, map, false).source(), InitialSource::kMap);
  EXPECT_EQ(InitialModel({}, scene_, no_map, false).source(), InitialSource::kSfm);
  // An explicit choice wins over the map; a resumed training takes its checkpoint and makes nothing.
  InitialModelOptions random;
  random.init = "random";
  EXPECT_EQ(InitialModel(random, scene_, map, false).source(), InitialSource::kRandom);
  const InitialModel resumed({}, scene_, map, true);
  EXPECT_EQ(resumed.source(), InitialSource::kCheckpoint);
  std::string what;
  EXPECT_EQ(resumed.make(TrainingData{}, &planes, 1000, what).size(), 0u);
  EXPECT_EQ(what, "the newest checkpoint");
}

TEST_F(InitialModelTest, AMapSeedingKeepsAtMostTheBudgetAndMaxInitPoints) {
  PlanarMap planes;
  const std::vector<Eigen::Vector3d> map = wall(100, planes);
  InitialModelOptions o;
  o.max_init_points = 30;
  const InitialModel initial(o, scene_, map, false);
  std::string what;
  // No training view (an empty TrainingData) sees the map: it seeds from all of it, within the caps.
  EXPECT_EQ(initial.make(TrainingData{}, &planes, 50, what).size(), 30u);
  EXPECT_EQ(what, "30 LiDAR map points");
  EXPECT_EQ(initial.make(TrainingData{}, &planes, 10, what).size(), 10u);
  // The same seed keeps the same subset.
  const kernels::GaussianModel a = initial.make(TrainingData{}, &planes, 10, what);
  const kernels::GaussianModel b = initial.make(TrainingData{}, &planes, 10, what);
  EXPECT_EQ(a.means, b.means);
  EXPECT_THROW(initial.make(TrainingData{}, nullptr, 10, what), std::logic_error);
}

TEST_F(InitialModelTest, FrontEndPointsAskedForButMissingNameTheCommandToRun) {
  InitialModelOptions o;
  o.init = "sfm";
  const std::vector<Eigen::Vector3d> no_map;
  std::string what;
  try {
    InitialModel(o, scene_, no_map, false).make(TrainingData{}, nullptr, 1000, what);
    FAIL() << "--init sfm without sfm/ was accepted";
  } catch (const std::invalid_argument& e) {
    EXPECT_NE(std::string(e.what()).find("run `litgs-engine match` first"), std::string::npos) << e.what();
  }
  write_front_end_points(4);
  EXPECT_EQ(InitialModel(o, scene_, no_map, false).make(TrainingData{}, nullptr, 1000, what).size(), 4u);
  EXPECT_NE(what.find("4 front-end points"), std::string::npos) << what;
}

}  // namespace
}  // namespace litgs::host
