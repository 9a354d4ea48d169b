// The scans in the solve (host/refine/scan_alignment.h): a room of three planes scanned from a line of
// frames. Through the true poses every scan lies on the map's planes; a frame placed off them by its prior
// is pulled back by its own scan, against an odometry prior that holds it where it was.
#include <gtest/gtest.h>

#include <random>

#include "host/refine/bundle_adjustment.h"
#include "host/refine/scan_alignment.h"

namespace litgs::host::refine {
namespace {

// Floor z = 0, walls x = 6 and y = 4, sampled on a 5 cm grid (in the world).
std::vector<Eigen::Vector3d> room() {
  std::vector<Eigen::Vector3d> pts;
  for (double a = 0; a < 6; a += 0.05)
    for (double b = 0; b < 4; b += 0.05) pts.emplace_back(a, b, 0);
  for (double a = 0; a < 4; a += 0.05)
    for (double b = 0.05; b < 2.5; b += 0.05) pts.emplace_back(6, a, b);
  for (double a = 0; a < 6; a += 0.05)
    for (double b = 0.05; b < 2.5; b += 0.05) pts.emplace_back(a, 4, b);
  return pts;
}

struct Rig {
  std::vector<CameraPose> truth;
  std::vector<RefineScan> scans;
};

// Ten frames along x, the LiDAR 10 cm above each camera; each scan sees the room within 5 m.
Rig scanned_room() {
  Rig rig;
  const std::vector<Eigen::Vector3d> world = room();
  Eigen::Isometry3d T_cam_lidar = Eigen::Isometry3d::Identity();
  T_cam_lidar.translation() = Eigen::Vector3d(0, 0, 0.1);
  for (uint32_t f = 0; f < 10; ++f) {
    CameraPose pose{0.1 * f,
                    Eigen::Quaterniond(Eigen::AngleAxisd(0.05 * f, Eigen::Vector3d::UnitZ())),
                    {1.0 + 0.3 * f, 1.5, 1.2}};
    rig.truth.push_back(pose);
    Eigen::Isometry3d T_world_cam = Eigen::Isometry3d::Identity();
    T_world_cam.linear() = pose.q_world_cam.toRotationMatrix();
    T_world_cam.translation() = pose.p_world_cam;
    const Eigen::Isometry3d lidar_world = (T_world_cam * T_cam_lidar).inverse();
    RefineScan scan{f, T_cam_lidar, {}};
    for (const auto& x : world)
      if ((x - pose.p_world_cam).norm() < 5) scan.points_lidar.push_back(lidar_world * x);
    rig.scans.push_back(std::move(scan));
  }
  return rig;
}

TEST(RefineScanAlignment, ScansThroughTheTruePosesLieOnTheirMapsPlanes) {
  const Rig rig = scanned_room();
  ScanAssociationReport report;
  // Round 2 maps at the finest voxel (0.1 m).
  const auto links = associate_scan_planes(rig.scans, rig.truth, 2, {}, report);
  EXPECT_EQ(report.scans, 10u);
  EXPECT_GT(report.planar_map_points, 1000u);
  EXPECT_GT(links.size(), 2000u);
  EXPECT_LT(scan_plane_rms_m(links, rig.truth), 0.002);
  // Round 0's 0.4 m voxels blur the room's edges: their plane fits tilt, and only the edges' points miss.
  const auto coarse = associate_scan_planes(rig.scans, rig.truth, 0, {}, report);
  EXPECT_GT(coarse.size(), 2000u);
  EXPECT_LT(scan_plane_rms_m(coarse, rig.truth), 0.02);
}

TEST(RefineScanAlignment, AFramePlacedOffTheRoomIsPulledBackByItsScan) {
  const Rig rig = scanned_room();
  std::vector<CameraPose> priors = rig.truth;
  const Eigen::Vector3d offset(0.06, -0.05, 0.04);
  priors[6].p_world_cam += offset;  // the odometry puts frame 6 off by 9 cm
  std::vector<CameraPose> poses = priors;
  ScanAssociationReport report;
  const double rms_before = scan_plane_rms_m(associate_scan_planes(rig.scans, poses, 0, {}, report), poses);
  std::vector<TrackPoint> no_points;
  for (size_t round = 0; round < 4; ++round) {
    const auto links = associate_scan_planes(rig.scans, poses, round, {}, report);
    BaProblem b;
    b.poses = &poses;
    b.priors = &priors;
    b.points = &no_points;
    b.scan_links = &links;
    const BaSolveSummary s = solve_bundle_adjustment(b);
    ASSERT_TRUE(s.usable) << s.brief;
    EXPECT_GT(s.scan_residuals, 0u);
  }
  const auto links = associate_scan_planes(rig.scans, poses, 4, {}, report);
  EXPECT_GT(rms_before, 0.005);
  EXPECT_LT(scan_plane_rms_m(links, poses), 0.003);
  // The map is built from all scans, frame 6's too, so the others move a little towards it (the whole
  // trajectory is free to shift together, held only by its priors): frame 6 is judged against them.
  Eigen::Vector3d shift = Eigen::Vector3d::Zero();
  for (size_t f = 0; f < poses.size(); ++f)
    if (f != 6) shift += (poses[f].p_world_cam - rig.truth[f].p_world_cam) / 9.0;
  EXPECT_LT(shift.norm(), 0.015);
  EXPECT_LT((poses[6].p_world_cam - rig.truth[6].p_world_cam - shift).norm(), 0.01);
  for (size_t f = 0; f < poses.size(); ++f) {
    if (f == 6) continue;
    EXPECT_LT((poses[f].p_world_cam - rig.truth[f].p_world_cam - shift).norm(), 0.005) << "frame " << f;
  }
  // Without the scans the priors keep frame 6 where the odometry put it.
  std::vector<CameraPose> held = priors;
  BaProblem b;
  b.poses = &held;
  b.priors = &priors;
  b.points = &no_points;
  solve_bundle_adjustment(b);
  EXPECT_GT((held[6].p_world_cam - rig.truth[6].p_world_cam).norm(), 0.08);
}

}  // namespace
}  // namespace litgs::host::refine
