// The generator's parts on their own: random streams, textures, ray casting, trajectory derivatives,
// LiDAR, IMU, the estimator's noise model, option checks.
#include <gtest/gtest.h>

#include <Eigen/Cholesky>
#include <cmath>
#include <numbers>

#include "host/synth/estimator_model.h"
#include "host/synth/geometry.h"
#include "host/synth/imu_sim.h"
#include "host/synth/lidar_sim.h"
#include "host/synth/presets.h"
#include "host/synth/rng.h"
#include "host/synth/thermal_camera.h"
#include "host/synth/thermal_texture.h"
#include "host/synth/trajectory.h"

namespace litgs::host::synth {
namespace {

using Eigen::Vector3d;

TEST(SynthRng, StreamsAreReproducibleAndIndependent) {
  Rng a(7, Stream::kLidar, 3), b(7, Stream::kLidar, 3), c(7, Stream::kLidar, 4), d(7, Stream::kImu, 3);
  const uint64_t va = a.next_u64();
  EXPECT_EQ(va, b.next_u64());
  EXPECT_NE(va, c.next_u64());
  EXPECT_NE(va, d.next_u64());
}

TEST(SynthRng, NormalHasUnitMomentsAndUniformIsInRange) {
  Rng rng(11);
  double sum = 0, sum2 = 0;
  const int n = 200000;
  for (int i = 0; i < n; ++i) {
    const double x = rng.normal();
    sum += x;
    sum2 += x * x;
    const double u = rng.uniform();
    ASSERT_GE(u, 0.0);
    ASSERT_LT(u, 1.0);
  }
  EXPECT_NEAR(sum / n, 0.0, 0.01);
  EXPECT_NEAR(sum2 / n, 1.0, 0.01);
  double hsum2 = 0;
  for (int i = 0; i < n; ++i) hsum2 += std::pow(hash_normal(static_cast<uint64_t>(i)), 2);
  EXPECT_NEAR(hsum2 / n, 1.0, 0.01);
}

TEST(SynthTexture, BrickJointsAreCoolerAndFadeToTheMeanWhenFiltered) {
  ThermalTexture t;
  t.pattern = ThermalPattern::kBrick;
  t.noise_raw = 0;
  t.cell_jitter_raw = 0;
  t.joint_raw = -20;
  // On a joint (cell border at v = 0.065) versus inside a brick, sharp.
  EXPECT_NEAR(thermal_radiance(t, 0.1, 0.065, 0), t.base_raw - 20, 1e-9);
  EXPECT_NEAR(thermal_radiance(t, 0.1, 0.03, 0), t.base_raw, 1e-9);
  // A footprint of many bricks averages to the joints' area share.
  const double share_u = t.joint_m / t.cell_u_m, share_v = t.joint_m / t.cell_v_m;
  const double expected = t.base_raw - 20 * (share_u + share_v - share_u * share_v);
  EXPECT_NEAR(thermal_radiance(t, 0.1, 0.03, 2.6), expected, 1.0);
}

TEST(SynthTexture, WeatheringIsDeterministicAndFadesWhenThePixelIsCoarserThanItsOctaves) {
  ThermalTexture t;
  t.noise_raw = 0;
  t.detail_raw = 30;
  t.detail_octaves = 6;
  t.detail_scale_m = 1;
  t.seed = 7;
  // A pure function of (u, v, footprint, seed).
  EXPECT_EQ(thermal_radiance(t, 0.37, 1.21, 0.01), thermal_radiance(t, 0.37, 1.21, 0.01));
  // Spread over a patch: fine footprints see every octave, a footprint coarser than the largest octave
  // sees none (the surface's mean).
  auto spread = [&](double footprint) {
    double lo = 1e9, hi = -1e9;
    for (int i = 0; i < 400; ++i) {
      const double r = thermal_radiance(t, 0.013 * i, 0.007 * i, footprint);
      lo = std::min(lo, r);
      hi = std::max(hi, r);
    }
    return hi - lo;
  };
  EXPECT_GT(spread(0.002), 20.0);
  EXPECT_EQ(spread(1.0), 0.0);
  t.seed = 8;
  EXPECT_NE(thermal_radiance(t, 0.37, 1.21, 0.01), [&] {
    ThermalTexture u = t;
    u.seed = 7;
    return thermal_radiance(u, 0.37, 1.21, 0.01);
  }());
}

TEST(SynthTexture, HeatLeaksAroundAnOpeningAndRisesAboveIt) {
  ThermalTexture t;
  t.noise_raw = 0;
  t.halos.push_back({1.0, 1.0, 2.0, 2.0, 50, 0.3});
  EXPECT_NEAR(thermal_radiance(t, 1.5, 2.0, 0), t.base_raw + 50, 1e-9);  // at the edge
  const double above = thermal_radiance(t, 1.5, 2.3, 0), below = thermal_radiance(t, 1.5, 0.7, 0);
  EXPECT_GT(above, below);  // heat rises: the halo reaches twice as far above
  EXPECT_NEAR(below - t.base_raw, 50 * std::exp(-0.5), 1e-9);
  EXPECT_NEAR(thermal_radiance(t, 5, 5, 0), t.base_raw, 1e-6);
}

TEST(SynthPresets, TheTexturedAppearanceAddsDetailTheFlatOneLacks) {
  for (const std::string& name : preset_names()) {
    const Preset textured = make_preset(name, 1), flat = make_preset(name, 1, Appearance::kFlat);
    ASSERT_EQ(textured.world.rects.size(), flat.world.rects.size()) << name;  // the same geometry
    for (const auto& t : flat.world.textures) EXPECT_EQ(t.detail_octaves, 0) << name;
    for (const auto& t : textured.world.textures) EXPECT_GT(t.detail_octaves, 0) << name;
    EXPECT_GT(textured.camera.blur_px, 0) << name;
    EXPECT_EQ(flat.camera.blur_px, 0) << name;
  }
  EXPECT_EQ(parse_appearance("flat"), Appearance::kFlat);
  EXPECT_THROW(parse_appearance("shiny"), std::invalid_argument);
}

TEST(SynthGeometry, RectHitsHolesAndCylinders) {
  World w;
  w.add_texture({});
  // A wall in the plane y = 5 with a hole; a pane 0.2 m behind it.
  w.add_wall(Vector3d(0, 5, 0), Vector3d::UnitX(), 10, 3, 0, {{{4, 1, 5, 2}, 0.2, 0}}, Vector3d(0, 0, 0));
  ASSERT_EQ(w.rects.size(), 2u);
  const auto planes = w.planes();
  EXPECT_NEAR(std::abs(planes[0].n.y()), 1.0, 1e-12);
  EXPECT_NEAR(std::abs(planes[0].d), 5.0, 1e-12);
  EXPECT_NEAR(std::abs(planes[1].d), 5.2, 1e-12);

  const auto wall_hit = w.cast({Vector3d(2, 0, 1.5), Vector3d::UnitY()}, 0, 100);
  ASSERT_TRUE(wall_hit);
  EXPECT_NEAR(wall_hit->range_m, 5, 1e-12);
  EXPECT_EQ(wall_hit->plane_id, 0);
  EXPECT_NEAR(wall_hit->normal.y(), -1, 1e-12);  // faces the ray
  const auto pane_hit = w.cast({Vector3d(4.5, 0, 1.5), Vector3d::UnitY()}, 0, 100);
  ASSERT_TRUE(pane_hit);
  EXPECT_NEAR(pane_hit->range_m, 5.2, 1e-12);
  EXPECT_EQ(pane_hit->plane_id, 1);
  EXPECT_FALSE(w.cast({Vector3d(2, 0, 1.5), -Vector3d::UnitY()}, 0, 100));
  EXPECT_FALSE(w.cast({Vector3d(2, 0, 1.5), Vector3d::UnitY()}, 0, 4.9));  // beyond max range

  w.cylinders.push_back({Eigen::Vector2d(2, 2), 0.5, 0, 3, 0});
  const auto cyl = w.cast({Vector3d(2, 0, 1.5), Vector3d::UnitY()}, 0, 100);
  ASSERT_TRUE(cyl);
  EXPECT_NEAR(cyl->range_m, 1.5, 1e-12);
  EXPECT_EQ(cyl->plane_id, -1);
  EXPECT_FALSE(w.cast({Vector3d(2, 0, 3.5), Vector3d::UnitY()}, 0, 100));  // over the cylinder and the wall
}

TEST(SynthGeometry, IndexGivesTheSameHitsAsTestingEveryPrimitive) {
  for (const std::string& name : preset_names()) {
    const Preset p = make_preset(name, 3);
    ASSERT_FALSE(p.world.bvh_nodes.empty());
    World brute = p.world;
    brute.bvh_nodes.clear();
    Rng rng(8);
    int hits = 0;
    for (int i = 0; i < 20000; ++i) {
      const Ray ray{Vector3d(rng.uniform(-5, 40), rng.uniform(-1.5, 1.5), rng.uniform(0.2, 2.6)),
                    Vector3d(rng.normal(), rng.normal(), rng.normal()).normalized()};
      const auto a = p.world.cast(ray, 0.01, 100), b = brute.cast(ray, 0.01, 100);
      ASSERT_EQ(a.has_value(), b.has_value()) << name << " ray " << i;
      if (!a) continue;
      ++hits;
      EXPECT_NEAR(a->range_m, b->range_m, 1e-12) << name << " ray " << i;
    }
    EXPECT_GT(hits, 10000) << name;
  }
}

TEST(SynthTrajectory, ClosedFormDerivativesMatchFiniteDifferences) {
  for (const std::string& name : preset_names()) {
    const Trajectory traj(make_preset(name, 1).trajectory);
    const double h = 1e-5;
    for (double t = 0.3; t < 8; t += 1.37) {
      const TrajectoryState s = traj.at(t), sp = traj.at(t + h), sm = traj.at(t - h);
      EXPECT_LT(((sp.p_world_m - sm.p_world_m) / (2 * h) - s.v_world_m_s).norm(), 1e-6) << name << " t=" << t;
      EXPECT_LT(((sp.v_world_m_s - sm.v_world_m_s) / (2 * h) - s.a_world_m_s2).norm(), 1e-5) << name;
      // R(t+h) = R(t) exp(omega h): the body-frame angular velocity.
      const Eigen::AngleAxisd d(s.R_world_body.transpose() * sp.R_world_body);
      EXPECT_LT((d.axis() * d.angle() / h - s.omega_body_rad_s).norm(), 1e-4) << name;
      EXPECT_NEAR(s.R_world_body.determinant(), 1, 1e-12);
    }
  }
}

TEST(SynthTrajectory, HasSlowAndFastSegments) {
  const Trajectory traj(make_preset("street", 1).trajectory);
  double lo = 1e9, hi = 0;
  for (double t = 0; t < 10; t += 0.05) {
    const double v = traj.at(t).v_world_m_s.norm();
    lo = std::min(lo, v);
    hi = std::max(hi, v);
  }
  EXPECT_LT(lo, 2.5);
  EXPECT_GT(hi, 9.5);
}

TEST(SynthLidar, SpinningScanOfAPlaneHasTheRangeNoise) {
  World w;
  w.add_texture({});
  w.add_rect({Vector3d(-5e3, -5e3, 0), Vector3d::UnitX(), Vector3d::UnitY(), 1e4, 1e4, {}, 0});  // ground
  LidarOptions o;
  o.range_noise_m = 0.02;
  o.range_max_m = 1e5;
  Eigen::Isometry3d T = Eigen::Isometry3d::Identity();
  T.translation() = Vector3d(0, 0, 2);
  Rng rng(5);
  const LidarScan scan = simulate_lidar_scan(w, T, 0, 0, o, rng);
  // Only downward beams hit: the elevations below 0 of 32 rings over [-25, 15].
  int down = 0;
  for (int b = 0; b < o.beams; ++b) down += (o.fov_down_deg + 40.0 * b / 31) < 0 ? 1 : 0;
  ASSERT_EQ(scan.points_lidar.size(), static_cast<size_t>(down * o.columns));
  double sum2 = 0;
  for (size_t i = 0; i < scan.points_lidar.size(); ++i) {
    EXPECT_NEAR(scan.true_world[i].z(), 0, 1e-9);
    EXPECT_EQ(scan.plane_id[i], 0);
    const double range_err = scan.points_lidar[i].norm() - (scan.true_world[i] - T.translation()).norm();
    sum2 += range_err * range_err;
  }
  EXPECT_NEAR(std::sqrt(sum2 / static_cast<double>(scan.points_lidar.size())), 0.02, 0.001);
}

TEST(SynthLidar, RosetteIsNonRepetitiveAndInsideItsCone) {
  World w;
  w.add_texture({});
  w.add_rect({Vector3d(5, -50, -50), Vector3d::UnitY(), Vector3d::UnitZ(), 100, 100, {}, 0});  // x = 5
  LidarOptions o;
  o.pattern = LidarPattern::kRosette;
  o.range_noise_m = 0;
  Rng rng(5);
  const auto a = simulate_lidar_scan(w, Eigen::Isometry3d::Identity(), 0, 0.0, o, rng);
  const auto b = simulate_lidar_scan(w, Eigen::Isometry3d::Identity(), 0.1, 0.1, o, rng);
  ASSERT_EQ(a.points_lidar.size(), static_cast<size_t>(o.rosette_points));
  const double max_off = std::tan(o.rosette_fov_deg / 2 * std::numbers::pi / 180) * 5 * 1.001;
  int same = 0;
  for (size_t i = 0; i < a.points_lidar.size(); ++i) {
    EXPECT_LE(std::hypot(a.points_lidar[i].y(), a.points_lidar[i].z()), max_off * std::sqrt(2.0));
    same += (a.points_lidar[i] - b.points_lidar[i]).norm() < 1e-3 ? 1 : 0;
  }
  EXPECT_LT(same, 10);  // the next scan looks elsewhere
}

TEST(SynthImu, AtRestReadsGravityUpPlusBias) {
  TrajectoryOptions o;
  o.speed_mean_m_s = 1e-9;
  o.speed_amplitude_m_s = 0;
  o.weave_amplitude_m = o.bob_amplitude_m = 0;
  o.yaw_amplitude_rad = o.pitch_amplitude_rad = o.roll_amplitude_rad = 0;
  const Trajectory traj(o);
  ImuOptions io;
  io.gyro_noise_rad_s = io.accel_noise_m_s2 = 0;
  Rng rng(3);
  ImuBias bias;
  const auto s = simulate_imu(traj, 100, 0, 1, io, rng, bias);
  ASSERT_EQ(s.size(), 201u);
  EXPECT_NEAR(s[1].t_s - s[0].t_s, 0.005, 1e-9);
  EXPECT_LT((s[100].accel_m_s2 - Vector3d(0, 0, 9.81) - bias.accel_m_s2).norm(), 1e-9);
  EXPECT_LT((s[100].gyro_rad_s - bias.gyro_rad_s).norm(), 1e-9);
  EXPECT_GT(bias.gyro_rad_s.norm(), 0);
}

TEST(SynthImu, IntegratedAccelerationMatchesTheVelocityChange) {
  // Independent of the closed-form acceleration: velocities from central differences of positions.
  const Trajectory traj(make_preset("street", 1).trajectory);
  ImuOptions o;
  Rng rng(12);
  ImuBias bias;
  const auto s = simulate_imu(traj, 0, 2.0, 3.0, o, rng, bias);
  ASSERT_EQ(s.size(), 201u);
  const Vector3d g(0, 0, -o.gravity_m_s2);
  Vector3d dv = Vector3d::Zero();
  double turned = 0;
  for (size_t k = 0; k + 1 < s.size(); ++k) {
    const double dt = s[k + 1].t_s - s[k].t_s;
    // Trapezoid of the world-frame acceleration R (f - b) + g with the true rotations.
    const Vector3d a0 = traj.at(s[k].t_s).R_world_body * (s[k].accel_m_s2 - bias.accel_m_s2) + g;
    const Vector3d a1 = traj.at(s[k + 1].t_s).R_world_body * (s[k + 1].accel_m_s2 - bias.accel_m_s2) + g;
    dv += 0.5 * (a0 + a1) * dt;
    turned += (s[k].gyro_rad_s - bias.gyro_rad_s).norm() * dt;
  }
  auto velocity = [&](double t) {
    const double h = 1e-4;
    return Vector3d((traj.at(t + h).p_world_m - traj.at(t - h).p_world_m) / (2 * h));
  };
  const Vector3d expected = velocity(3.0) - velocity(2.0);
  EXPECT_GT(expected.norm(), 1.0);  // the street rig accelerates hard
  EXPECT_LT((dv - expected).norm(), 0.03) << dv.transpose() << " vs " << expected.transpose();
  EXPECT_GT(turned, 0.02);
}

TEST(SynthEstimator, DriftGrowsWithDistanceAtTheStatedRate) {
  std::vector<io::TumPose> truth(50);
  std::vector<double> dist(50);
  for (int i = 0; i < 50; ++i) {
    truth[i].t_s = i;
    truth[i].p_world = Vector3d(i, 0, 0);
    dist[i] = i;
  }
  EstimatorNoiseOptions o;
  o.pose_noise_m = 0;
  o.pose_noise_rad = 0;
  o.drift_rad_per_m = 0;
  Rng rng(9);
  const auto est = drift_poses(truth, dist, o, rng);
  for (int i = 0; i < 50; ++i)
    EXPECT_NEAR((est[i].p_world - truth[i].p_world).norm(), o.drift_m_per_m * i, 1e-12);
}

TEST(SynthEstimator, AnchorErrorsFollowTheirCovariance) {
  const Preset p = make_preset("facade", 2);
  const io::CameraIntrinsics K = p.camera.intrinsics();
  Eigen::Isometry3d T = p.T_imu_cam;
  T.translation() += Vector3d(3, 0, 1.5);
  Rng rng(4);
  std::vector<Vector3d> truth;
  EstimatorNoiseOptions o = p.estimator;
  o.anchors_per_frame = 2000;
  const auto anchors = pick_anchors(p.world, K, T, o, rng, truth);
  ASSERT_GT(anchors.size(), 300u);
  double chi2 = 0;
  for (size_t i = 0; i < anchors.size(); ++i) {
    const Vector3d e = anchors[i].p_world - truth[i];
    chi2 += e.dot(anchors[i].cov_m2.ldlt().solve(e));
  }
  EXPECT_NEAR(chi2 / static_cast<double>(anchors.size()), 3.0, 0.35);  // chi-square with 3 degrees of freedom
}

TEST(SynthOptionsCheck, NamesTheBadField) {
  EXPECT_EQ(LidarOptions{}.check(), "");
  LidarOptions l;
  l.beams = 0;
  EXPECT_NE(l.check().find("beams"), std::string::npos);
  ThermalCameraOptions c;
  c.width = 0;
  EXPECT_NE(c.check().find("width"), std::string::npos);
  TrajectoryOptions t;
  t.speed_amplitude_m_s = 5;
  EXPECT_NE(t.check().find("speed_amplitude_m_s"), std::string::npos);
  EXPECT_THROW(Trajectory{t}, std::invalid_argument);
  EXPECT_THROW(make_preset("moon", 1), std::invalid_argument);
}

}  // namespace
}  // namespace litgs::host::synth
