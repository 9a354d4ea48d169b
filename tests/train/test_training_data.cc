// Training data from the real DUNR thermal scene (imported from its Metashape project with its 45 8-bit
// frames, tests/data/thermitage-dunr/radjpg): the intensity mappings, held-out split, undistorted downscaled
// cameras; initialization from the COLMAP points in the control-point frame (the scene's recentring must
// apply to them); LiDAR plane fits.
#include <gtest/gtest.h>
#include <unistd.h>

#include <cmath>
#include <filesystem>
#include <random>

#include "host/train/init_gaussians.h"
#include "host/train/lidar_planes.h"
#include "host/train/training_data.h"
#include "io/import_metashape.h"
#include "tests/support/test_data.h"

namespace litgs::host {
namespace {

namespace fs = std::filesystem;
// Throws (the suite fails, naming the path) when the data is missing.
fs::path dunr() {
  return testing::test_data("thermitage-dunr");
}

class DunrScene : public ::testing::Test {
 protected:
  static void SetUpTestSuite() {
    dir_ = fs::temp_directory_path() / ("litgs-train-dunr-" + std::to_string(::getpid()));
    fs::remove_all(dir_);
    io::MetashapeImportOptions o;
    o.xml = dunr() / "metashape" / "DUNR-ImgCoords-TIR.xml";
    o.images = dunr() / "radjpg";
    o.out = dir_;
    io::import_metashape(o);
    TrainingDataOptions t;
    t.downscale = 2.0;
    data_ = new TrainingData(load_training_data(dir_, t));
  }
  static void TearDownTestSuite() {
    delete data_;
    fs::remove_all(dir_);
  }
  static inline fs::path dir_;
  static inline TrainingData* data_ = nullptr;
};

TEST_F(DunrScene, EightBitFramesMapLinearlyByDefault) {
  // kAuto on 8-bit frames: value / 255, no stretch.
  EXPECT_EQ(data_->stretch_low, 0.0);
  EXPECT_EQ(data_->stretch_high, 255.0);
  double lo = 1, hi = 0, mean = 0;
  size_t n = 0;
  for (const auto& v : data_->views)
    for (float x : v.image) {
      lo = std::min<double>(lo, x), hi = std::max<double>(hi, x), mean += x;
      ++n;
    }
  EXPECT_GE(lo, 0.0);
  EXPECT_LE(hi, 1.0);
  mean /= static_cast<double>(n);
  // djpeg's decode of the 45 frames has mean 113.2 / 255 = 0.444 at full size (downscaling averages).
  EXPECT_NEAR(mean, 0.444, 0.01);
}

TEST_F(DunrScene, SharedPercentileStretchOverAllFrames) {
  // The 0.5 and 99.5 percentiles of all 45 frames' values together, not per frame: 0 and 238 as computed
  // independently from djpeg's decode of the frames (tests/data/thermitage-dunr/PROVENANCE.md).
  TrainingDataOptions t;
  t.downscale = 2.0;
  t.mapping = IntensityMapping::kPercentile;
  const TrainingData d = load_training_data(dir_, t);
  EXPECT_NEAR(d.stretch_low, 0, 1);
  EXPECT_NEAR(d.stretch_high, 238, 1);
  size_t at_one = 0, n = 0;
  for (const auto& v : d.views)
    for (float x : v.image) at_one += x == 1.0f, ++n;
  EXPECT_GT(at_one, 0u) << "the brightest 0.5% clamp to 1";
  EXPECT_LT(at_one, n / 100) << "about 0.5% of pixels lie above the high percentile";
}

TEST_F(DunrScene, ViewsHeldOutAndCameras) {
  ASSERT_EQ(data_->views.size() + data_->frozen_skipped, 45u);
  size_t heldout = 0;
  for (const auto& v : data_->views) heldout += v.heldout;
  EXPECT_EQ(heldout, 6u) << "frames 0, 8, ..., 40";
  EXPECT_EQ(data_->width, 320u);
  EXPECT_EQ(data_->height, 256u);
  const auto& c = data_->views[0].camera;
  EXPECT_NEAR(c.fx, 767.0 / 2.0, 15.0);
  EXPECT_NEAR(c.cx, 160.0, 20.0);
  EXPECT_GT(data_->scene_extent_m, 1.0);
  EXPECT_LT(data_->scene_extent_m, 100.0);
}

TEST_F(DunrScene, TruePosesOnASceneWithoutGroundTruthIsAnError) {
  TrainingDataOptions t;
  t.downscale = 2.0;
  t.true_poses = true;
  try {
    load_training_data(dir_, t);
    FAIL() << "expected an error";
  } catch (const std::invalid_argument& e) {
    EXPECT_NE(std::string(e.what()).find("gt/poses.txt"), std::string::npos) << e.what();
  }
}

TEST_F(DunrScene, ColmapPointsLandInFrontOfTheCamerasAfterRecentring) {
  const InitPoints file = load_points(dunr() / "colmap-triangulated-points.ply", data_->world_offset_m);
  EXPECT_TRUE(file.covariances.empty()) << "the COLMAP points carry no covariance";
  const std::vector<Eigen::Vector3d>& pts = file.positions;
  ASSERT_EQ(pts.size(), 3988u);
  size_t seen = 0;
  for (const auto& p : pts) {
    bool visible = false;
    for (const auto& v : data_->views) {
      const auto& c = v.camera;
      const glm::dvec3 q = c.R_cam_world * glm::dvec3(p.x(), p.y(), p.z()) + c.t_cam_world;
      const double u = c.fx * q.x / q.z + c.cx, w = c.fy * q.y / q.z + c.cy;
      if (q.z > 0.1 && u >= 0 && w >= 0 && u < c.width && w < c.height) visible = true;
    }
    seen += visible;
  }
  EXPECT_GT(seen, pts.size() * 95 / 100) << "recentred points project into the views";
  const auto model = init_from_points(pts, *data_, InitOptions{});
  ASSERT_EQ(model.size(), pts.size());
  EXPECT_NO_THROW(model.check());
  for (float s : model.log_scales) ASSERT_TRUE(std::isfinite(s));
  // Colours sampled from the views: not all the 0.5 gray of unseen points.
  size_t coloured = 0;
  for (size_t i = 0; i < model.size(); ++i) coloured += model.sh[i * model.sh_coeffs()] != 0.0f;
  EXPECT_GT(coloured, model.size() * 9 / 10);
}

// A 40x30 camera at the origin looking down +z.
kernels::SplatCamera camera_at_origin() {
  kernels::SplatCamera cam;
  cam.width = 40;
  cam.height = 30;
  cam.fx = cam.fy = 40;
  cam.cx = 20;
  cam.cy = 15;
  return cam;
}

TEST(LidarPlanes, PlaneAndCornerPoints) {
  // A noisy plane z = 2 and a few points of a pole in front of it.
  std::mt19937 rng(1);
  std::normal_distribution<double> noise(0.0, 0.002);
  std::vector<Eigen::Vector3d> pts;
  for (int i = -20; i <= 20; ++i)
    for (int j = -20; j <= 20; ++j) pts.emplace_back(0.05 * i, 0.05 * j, 2.0 + noise(rng));
  const PlanarMap map = fit_planes(pts, PlaneFitOptions{});
  EXPECT_GT(map.planar_count(), pts.size() * 9 / 10);
  for (size_t i = 0; i < pts.size(); ++i)
    if (map.planar[i]) {
      ASSERT_GT(std::abs(map.normals[i].z()), 0.98f);
    }
  const kernels::SplatCamera cam = camera_at_origin();
  const ViewPlaneMaps v = project_planes(map, cam);
  EXPECT_GT(v.valid_count, 300u);
  for (size_t p = 0; p < size_t{40} * 30; ++p)
    if (v.points[4 * p + 3] == 1.0f) {
      ASSERT_NEAR(v.points[4 * p + 2], 2.0f, 0.02f);
    }
}

TEST(LidarPlanes, PixelsCarryPointsMovedOntoTheirLocalPlane) {
  // A plane z = 2 sampled with 2 cm range noise (the synthetic facade's LiDAR): the raw points scatter 2 cm
  // about it, the points the loss sees (moved onto the local fit) must scatter far less.
  std::mt19937 rng(3);
  std::normal_distribution<double> noise(0.0, 0.02);
  std::vector<Eigen::Vector3d> pts;
  for (int i = -30; i <= 30; ++i)
    for (int j = -30; j <= 30; ++j) pts.emplace_back(0.04 * i, 0.04 * j, 2.0 + noise(rng));
  PlaneFitOptions fit;
  fit.max_flatness = 0.5;  // noise this large relative to the spacing: accept the fit
  const PlanarMap map = fit_planes(pts, fit);
  const kernels::SplatCamera cam = camera_at_origin();
  const ViewPlaneMaps v = project_planes(map, cam);
  ASSERT_GT(v.valid_count, 300u);
  double raw_sq = 0, moved_sq = 0;
  for (const auto& p : pts) raw_sq += (p.z() - 2.0) * (p.z() - 2.0);
  for (size_t p = 0; p < size_t{40} * 30; ++p)
    if (v.points[4 * p + 3] == 1.0f) {
      const double n_z = v.normals[4 * p + 2], off = v.points[4 * p + 2] - 2.0;
      moved_sq += off * off * n_z * n_z;  // the residual along the normal, what the loss measures
    }
  const double raw_rms = std::sqrt(raw_sq / static_cast<double>(pts.size()));
  const double moved_rms = std::sqrt(moved_sq / v.valid_count);
  EXPECT_NEAR(raw_rms, 0.02, 0.002);
  EXPECT_LT(moved_rms, 0.4 * raw_rms) << "raw " << raw_rms << " m, on the local planes " << moved_rms << " m";
}

}  // namespace
}  // namespace litgs::host

namespace litgs::host {
namespace {

TEST(PlaneDistanceTest, DistancesAndRobustBound) {
  std::vector<Eigen::Vector3d> pts;
  for (int i = -10; i <= 10; ++i)
    for (int j = -10; j <= 10; ++j) pts.emplace_back(0.05 * i, 0.05 * j, 2.0);
  const PlanarMap map = fit_planes(pts, PlaneFitOptions{});
  const PlaneDistance index(map);
  // On the plane, 3 cm off it, 40 cm off it (near enough to have a plane point), and far from any point.
  const std::vector<float> means = {0.1f, 0.1f, 2.0f, 0.1f, 0.1f, 2.03f, 0.0f, 0.0f, 2.4f, 5.0f, 5.0f, 5.0f};
  const auto d = index.distances(means);
  ASSERT_EQ(d.size(), 4u);
  EXPECT_NEAR(d[0], 0.0f, 1e-5f);
  EXPECT_NEAR(d[1], 0.03f, 1e-5f);
  EXPECT_NEAR(d[2], 0.4f, 1e-5f);
  EXPECT_TRUE(std::isnan(d[3])) << "no plane within reach: never pruned";
  // 1000 inliers around 1 cm and 3 outliers: the bound keeps the inliers and cuts the outliers.
  std::vector<float> many(1000);
  std::mt19937 rng(2);
  std::uniform_real_distribution<float> u(0.0f, 0.02f);
  for (auto& x : many) x = u(rng);
  many.insert(many.end(), {0.5f, 0.8f, 2.0f});
  const float bound = PlaneDistance::robust_bound(many);
  EXPECT_GE(bound, 0.1f) << "never below the floor";
  EXPECT_LT(bound, 0.5f);
}

TEST(PlaneDistanceTest, AQueryNearestToNonPlanarPointsHasNoPlane) {
  // A wall (z = 2) and, 30 cm in front of it, a random clump (a bush): the clump's points are not planar.
  std::vector<Eigen::Vector3d> pts;
  for (int i = -20; i <= 20; ++i)
    for (int j = -20; j <= 20; ++j) pts.emplace_back(0.05 * i, 0.05 * j, 2.0);
  std::mt19937 rng(4);
  std::uniform_real_distribution<double> u(-0.1, 0.1);
  for (int k = 0; k < 300; ++k) pts.emplace_back(0.5 + u(rng), 0.5 + u(rng), 1.7 + u(rng));
  const PlanarMap map = fit_planes(pts, PlaneFitOptions{});
  const PlaneDistance index(map);
  // Inside the clump (nearest point: the clump) and beside it on the wall.
  const auto d = index.distances({0.5f, 0.5f, 1.7f, -0.5f, -0.5f, 2.01f});
  EXPECT_TRUE(std::isnan(d[0])) << "a Gaussian on the bush is measured against the wall: " << d[0];
  EXPECT_NEAR(d[1], 0.01f, 1e-4f);
}

}  // namespace
}  // namespace litgs::host
