// The scan check (host/refine/scan_check.h) on real LiDAR: small_gicp's example pair, two scans and their
// reference relative pose (tests/data/small-gicp-pair). The target scan makes the map as `litgs-engine map`
// builds it (averaged per 10 cm voxel, local plane fits); the source scan is the held-out one. The synthetic
// tests use exact planes; real returns add range noise, edges, clutter and sparse far surfaces, and the
// check must still tell a right pose from a wrong one by centimetres.
#include <gtest/gtest.h>

#include <Eigen/Geometry>
#include <fstream>
#include <iostream>

#include "host/lidar_map/map_builder.h"
#include "host/refine/scan_check.h"
#include "io/ply_points.h"
#include "tests/support/test_data.h"

namespace litgs::host::refine {
namespace {

Eigen::Matrix4d read_matrix(const std::filesystem::path& path) {
  std::ifstream in(path);
  Eigen::Matrix4d m;
  for (int r = 0; r < 4; ++r)
    for (int c = 0; c < 4; ++c) in >> m(r, c);
  EXPECT_TRUE(in) << path;
  return m;
}

PlanarMap map_of(const io::PointCloud& scan) {
  LidarMapOptions options;
  options.holdout_every = 0;
  LidarMapReport report;
  const io::PointCloud map = build_lidar_map(
      {0.0}, [&](size_t) { return scan; },
      [](double) { return Eigen::Matrix4d(Eigen::Matrix4d::Identity()); }, options, report);
  return fit_planes(map.positions, {});
}

ScanVerdict judge(const PlanarMap& map, const io::PointCloud& scan, const Eigen::Matrix4d& prior,
                  const Eigen::Matrix4d& refined) {
  CheckedScan checked;
  checked.points_lidar = scan.positions;
  checked.T_world_lidar_prior = prior;
  checked.T_world_lidar_refined = refined;
  return judge_on_scans(map, map, {checked}, {});
}

TEST(RefineScanCheck, OnARealPairOfScansTheReferencePoseBeatsOneFiveCentimetresOrHalfADegreeOff) {
  const io::PointCloud target = io::read_ply_points(litgs::testing::test_data("small-gicp-pair/target.ply")),
                       source = io::read_ply_points(litgs::testing::test_data("small-gicp-pair/source.ply"));
  const Eigen::Matrix4d T_target_source =
      read_matrix(litgs::testing::test_data("small-gicp-pair/T_target_source.txt"));
  const PlanarMap map = map_of(target);
  ASSERT_GT(map.planar_count(), 1000u);

  std::vector<std::pair<std::string, Eigen::Matrix4d>> wrong;
  for (int axis = 0; axis < 3; ++axis) {
    Eigen::Matrix4d shifted = T_target_source;
    shifted(axis, 3) += 0.05;
    wrong.emplace_back("5 cm along axis " + std::to_string(axis), shifted);
    Eigen::Matrix4d turned = T_target_source;
    // Turned about the source scan's origin, as a wrong orientation of its LiDAR would place it.
    turned.topLeftCorner<3, 3>() =
        Eigen::AngleAxisd(0.5 * M_PI / 180, Eigen::Vector3d::Unit(axis)).toRotationMatrix() *
        T_target_source.topLeftCorner<3, 3>();
    wrong.emplace_back("0.5 degrees about axis " + std::to_string(axis), turned);
  }
  for (const auto& [what, T_wrong] : wrong) {
    // The reference pose as the refined one against a wrong prior: kept; the other way round: turned down.
    const ScanVerdict better = judge(map, source, T_wrong, T_target_source);
    const ScanVerdict worse = judge(map, source, T_target_source, T_wrong);
    ASSERT_TRUE(better.measured) << what;
    std::cout << what << ": " << worse.summary << "\n";
    EXPECT_TRUE(better.keep_refined) << what << ": " << better.summary;
    EXPECT_FALSE(worse.keep_refined) << what << ": " << worse.summary;
  }
}

}  // namespace
}  // namespace litgs::host::refine
