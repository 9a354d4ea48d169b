// The LiDAR map from scans: deskewing by per-point time, voxel averaging, plane fits, the scene wrapper.
#include <gtest/gtest.h>

#include <filesystem>

#include "host/lidar_map/map_builder.h"
#include "host/synth/synth.h"
#include "io/pcd.h"
#include "io/scene.h"
#include "io/scene_text.h"

namespace litgs::host {
namespace {

// The LiDAR moves along +x at 10 m/s; during a 0.1 s sweep it samples the wall x = 5 (world). In the sensor
// frame each point is the wall point minus the position at its own time.
struct MovingScan {
  std::vector<double> times = {0.0};
  io::PointCloud cloud;
  LidarPoseAt pose = [](double t) -> std::optional<Eigen::Matrix4d> {
    Eigen::Matrix4d T = Eigen::Matrix4d::Identity();
    T(0, 3) = 10 * t;
    return T;
  };
  MovingScan() {
    io::ScalarField time{"time", {}};
    for (int i = 0; i < 2000; ++i) {
      const double dt = 0.1 * i / 1999.0;
      const Eigen::Vector3d wall(5, -3 + 6 * ((i * 37) % 2000) / 2000.0, -1 + 2 * ((i * 91) % 2000) / 2000.0);
      cloud.positions.push_back(wall - Eigen::Vector3d(10 * dt, 0, 0));
      time.values.push_back(dt);
    }
    cloud.extra.push_back(time);
  }
};

double max_wall_error(const io::PointCloud& map) {
  double worst = 0;
  for (const auto& p : map.positions) worst = std::max(worst, std::abs(p.x() - 5));
  return worst;
}

TEST(LidarMap, DeskewPlacesEachPointWithItsOwnTime) {
  MovingScan s;
  LidarMapOptions o;
  LidarMapReport r;
  const io::PointCloud map = build_lidar_map(
      s.times, [&](size_t) { return s.cloud; }, s.pose, o, r);
  EXPECT_EQ(r.scans_deskewed, 1u);
  // Voxel centroids of points on x = 5 stay on it (interpolation between the 8 sampled poses is exact here).
  EXPECT_LT(max_wall_error(map), 1e-9);
  // Every planar normal is the wall's.
  size_t planar = 0;
  for (size_t i = 0; i < map.size(); ++i)
    if (map.normals[i].norm() > 0) {
      EXPECT_GT(std::abs(map.normals[i].x()), 0.999f);
      EXPECT_GT(map.field("planarity")->values[i], 0.95);
      ++planar;
    }
  EXPECT_GT(planar, map.size() / 2);
  // Without deskewing, the 1 m of motion during the sweep smears the wall.
  o.deskew = false;
  LidarMapReport r2;
  const io::PointCloud smeared = build_lidar_map(
      s.times, [&](size_t) { return s.cloud; }, s.pose, o, r2);
  EXPECT_GT(max_wall_error(smeared), 0.5);
}

TEST(LidarMap, ScansOutsideTheTrajectoryAreSkippedAndCounted) {
  MovingScan s;
  LidarPoseAt none = [](double) -> std::optional<Eigen::Matrix4d> { return std::nullopt; };
  LidarMapReport r;
  const io::PointCloud map = build_lidar_map(
      s.times, [&](size_t) { return s.cloud; }, none, {}, r);
  EXPECT_EQ(map.size(), 0u);
  EXPECT_EQ(r.scans_without_pose, 1u);
}

TEST(LidarMap, SyntheticSceneMapLiesOnTheTruePlanes) {
  const std::filesystem::path dir = std::filesystem::temp_directory_path() / "litgs_lidar_map_scene";
  std::filesystem::remove_all(dir);
  synth::SynthOptions so;
  so.frames = 6;
  so.width = 64;
  so.height = 48;
  so.out = dir;
  synth::generate_synthetic_scene(so);
  // The scene already has a map: kept unless asked.
  EXPECT_THROW(write_scene_lidar_map(dir, {}), std::invalid_argument);
  const std::filesystem::path out = dir / "built.pcd";
  const LidarMapReport r = write_scene_lidar_map(dir, {}, out);
  EXPECT_EQ(r.scans, 6u);
  const io::PointCloud map = io::read_pcd(out);
  ASSERT_GT(map.size(), 1000u);
  const std::vector<io::Plane> planes = io::read_planes(dir / "gt/planes.txt");
  // Placed with the drifting estimated poses (a few mm over 6 frames) and 1.5 cm range noise averaged
  // per 10 cm voxel: the median distance to the nearest true plane is well under 2 cm.
  std::vector<double> d;
  for (const auto& p : map.positions) {
    double best = 1e9;
    for (const auto& pl : planes) best = std::min(best, std::abs(pl.n.dot(p) + pl.d));
    d.push_back(best);
  }
  std::nth_element(d.begin(), d.begin() + static_cast<long>(d.size() / 2), d.end());
  EXPECT_LT(d[d.size() / 2], 0.02);
  std::filesystem::remove_all(dir);
}

// Scans 0, N, 2N, ... stay out of the map and form lidar/heldout.pcd; scene.yaml records N so that refine's
// scan check and eval's geometry use the same scans. Too few scans: none held out, and the report says so.
TEST(LidarMap, EveryEighthScanIsHeldOutOfTheMapAndRecorded) {
  const std::filesystem::path dir = std::filesystem::temp_directory_path() / "litgs_lidar_map_holdout";
  std::filesystem::remove_all(dir);
  synth::SynthOptions so;
  so.frames = 17;
  so.width = 64;
  so.height = 48;
  so.out = dir;
  synth::generate_synthetic_scene(so);
  EXPECT_EQ(io::read_scene(dir, {false, false}).config.lidar_holdout_every, 8);  // synth holds out too
  const LidarMapReport r = write_scene_lidar_map(dir, {}, {}, true);
  EXPECT_EQ(r.scans, 14u);  // 17 less scans 0, 8, 16
  EXPECT_EQ(r.scans_heldout, 3u);
  const io::Scene scene = io::read_scene(dir, {false, true});
  EXPECT_EQ(scene.config.lidar_holdout_every, 8);
  ASSERT_TRUE(std::filesystem::exists(dir / io::kHeldoutScansMap));
  EXPECT_EQ(io::read_pcd(dir / io::kHeldoutScansMap).size(), r.heldout_points);
  EXPECT_GT(r.heldout_points, 100u);

  LidarMapOptions all;
  all.holdout_every = 0;
  const LidarMapReport whole = write_scene_lidar_map(dir, all, {}, true);
  EXPECT_EQ(whole.scans, 17u);
  EXPECT_EQ(io::read_scene(dir, {false, false}).config.lidar_holdout_every, 0);
  EXPECT_FALSE(std::filesystem::exists(dir / io::kHeldoutScansMap));  // a stale one would mislead eval

  LidarMapOptions wide;
  wide.holdout_every = 9;  // 17 scans < 2 x 9: none held out
  const LidarMapReport none = write_scene_lidar_map(dir, wide, {}, true);
  EXPECT_EQ(none.scans, 17u);
  EXPECT_EQ(none.scans_heldout, 0u);
  ASSERT_FALSE(none.notes.empty());
  EXPECT_NE(none.notes.back().find("no scan held out"), std::string::npos);
  EXPECT_THROW(
      [] {
        LidarMapOptions bad;
        bad.holdout_every = 1;
        bad.check();
      }(),
      std::invalid_argument);
  std::filesystem::remove_all(dir);
}

}  // namespace
}  // namespace litgs::host
