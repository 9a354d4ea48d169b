// LiDAR simulation: a spinning multi-beam pattern or a Livox-like non-repetitive rosette, ray cast against
// the world from the true pose, with Gaussian range noise. Scans are instantaneous (motion-compensated, as
// an upstream estimator hands them on). LiDAR frame: x forward, y left, z up.
#pragma once

#include <Eigen/Core>
#include <Eigen/Geometry>
#include <string>
#include <vector>

#include "host/synth/geometry.h"
#include "host/synth/rng.h"
#include "io/point_cloud.h"
#include "io/scene_types.h"

namespace litgs::host::synth {

enum class LidarPattern {
  kSpinning,  // `beams` rings over [fov_down_deg, fov_up_deg] times `columns` azimuths over 360 degrees
  kRosette,   // two counter-rotating prisms (Livox Avia-like): non-repetitive, forward-looking
};

struct LidarOptions {
  LidarPattern pattern = LidarPattern::kSpinning;
  int beams = 32;                // spinning: number of rings
  double fov_down_deg = -25;     // spinning: elevation of the lowest ring
  double fov_up_deg = 15;        // spinning: elevation of the highest ring
  int columns = 512;             // spinning: azimuth steps per revolution
  int rosette_points = 12000;    // rosette: points per scan
  double rosette_fov_deg = 70;   // rosette: full cone angle of the pattern
  double range_min_m = 0.5;      // returns closer than this are dropped
  double range_max_m = 60;       // and farther than this
  double range_noise_m = 0.015;  // standard deviation of the range error, along the beam
  // The beam's full divergence (0: an ideal ray). A beam returns from the nearest surface any part of its
  // footprint touches (five rays: the centre and four at half the divergence), placed along its centre ray:
  // at an edge, the nearer surface seems to reach up to half a footprint past it.
  double beam_divergence_rad = 0;

  std::string check() const;  // empty if valid, else the first bad field and why
};

// One scan: noisy points in the LiDAR frame and, index for index, the noise-free world points and the
// plane each return hit (-1 for a curved surface).
struct LidarScan {
  double t_s = 0;
  std::vector<Eigen::Vector3d> points_lidar;  // [N] noisy, sensor frame
  std::vector<Eigen::Vector3d> true_world;    // [N] exact hit points, world frame
  std::vector<int> plane_id;                  // [N]
};

// `t_pattern_s` advances the rosette so that consecutive scans cover new directions.
LidarScan simulate_lidar_scan(const World& world, const Eigen::Isometry3d& T_world_lidar, double t_s,
                              double t_pattern_s, const LidarOptions& options, Rng& rng);

// The world LiDAR map: scans placed with their true poses (noise kept), voxel-downsampled by keeping the
// first point of each voxel (no averaging across the edges of planes), and the matching noise-free map
// with a `plane_id` field (index into gt/planes.txt, -1 for curved surfaces). Point i of both is the same
// return.
struct LidarMaps {
  io::PointCloud noisy;
  io::PointCloud truth;
};
// Scans the map holds out (io::is_heldout_scan with `holdout_every`) are in neither map.
LidarMaps accumulate_lidar_map(const std::vector<LidarScan>& scans,
                               const std::vector<Eigen::Isometry3d>& T_world_lidar, double voxel_m,
                               int holdout_every = 0);

}  // namespace litgs::host::synth
