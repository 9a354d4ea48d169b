#include "host/synth/lidar_sim.h"

#include <algorithm>
#include <cmath>
#include <numbers>
#include <stdexcept>
#include <unordered_map>

namespace litgs::host::synth {
namespace {
constexpr double kDeg = std::numbers::pi / 180;
}

std::string LidarOptions::check() const {
  if (pattern == LidarPattern::kSpinning) {
    if (beams < 1 || beams > 256) return "beams: must be in [1, 256]";
    if (columns < 1 || columns > 100000) return "columns: must be in [1, 100000]";
    if (!(fov_down_deg >= -90 && fov_down_deg < fov_up_deg && fov_up_deg <= 90))
      return "fov_down_deg/fov_up_deg: need -90 <= down < up <= 90";
  } else {
    if (rosette_points < 1 || rosette_points > 10000000) return "rosette_points: must be in [1, 1e7]";
    if (!(rosette_fov_deg > 0 && rosette_fov_deg < 170)) return "rosette_fov_deg: must be in (0, 170)";
  }
  if (!(range_min_m >= 0 && range_max_m > range_min_m)) return "range_min_m/range_max_m: need 0 <= min < max";
  if (!(range_noise_m >= 0)) return "range_noise_m: must be >= 0";
  if (!(beam_divergence_rad >= 0 && beam_divergence_rad < 0.1))
    return "beam_divergence_rad: must be in [0, 0.1)";
  return "";
}

LidarScan simulate_lidar_scan(const World& world, const Eigen::Isometry3d& T_world_lidar, double t_s,
                              double t_pattern_s, const LidarOptions& o, Rng& rng) {
  LidarScan scan;
  scan.t_s = t_s;
  const Eigen::Matrix3d R = T_world_lidar.linear();
  const Eigen::Vector3d origin = T_world_lidar.translation();
  auto shoot = [&](const Eigen::Vector3d& dir_lidar) {
    const Eigen::Vector3d dir = R * dir_lidar;
    auto hit = world.cast({origin, dir}, o.range_min_m, o.range_max_m);
    if (o.beam_divergence_rad > 0) {
      // The footprint returns from the nearest surface any of its rays meets, at the mean range of the rays
      // that meet that surface: the centre's range inside a surface, a nearer one at its edge.
      const Eigen::Vector3d a = dir.unitOrthogonal(), b = dir.cross(a);
      const double h = std::tan(o.beam_divergence_rad / 2);
      std::vector<Hit> hits;
      if (hit) hits.push_back(*hit);
      for (const Eigen::Vector3d& off : {a, Eigen::Vector3d(-a), b, Eigen::Vector3d(-b)})
        if (const auto edge =
                world.cast({origin, (dir + h * off).normalized()}, o.range_min_m, o.range_max_m))
          hits.push_back(*edge);
      if (!hits.empty()) {
        const Hit nearest = *std::min_element(
            hits.begin(), hits.end(), [](const Hit& x, const Hit& y) { return x.range_m < y.range_m; });
        double sum = 0;
        int n = 0;
        for (const Hit& x : hits)
          if (x.plane_id == nearest.plane_id && x.texture == nearest.texture &&
              x.range_m < nearest.range_m + 0.5) {
            sum += x.range_m;
            ++n;
          }
        hit = hit && hit->plane_id == nearest.plane_id ? hit : nearest;
        hit->range_m = sum / n;
      }
    }
    const double noise = o.range_noise_m * rng.normal();  // drawn for every beam: misses keep streams aligned
    if (!hit) return;
    scan.points_lidar.push_back(dir_lidar * (hit->range_m + noise));
    scan.true_world.push_back(hit->point);
    scan.plane_id.push_back(hit->plane_id);
  };
  if (o.pattern == LidarPattern::kSpinning) {
    for (int c = 0; c < o.columns; ++c) {
      const double az = 2 * std::numbers::pi * c / o.columns;
      for (int b = 0; b < o.beams; ++b) {
        const double el =
            (o.beams == 1 ? o.fov_down_deg
                          : o.fov_down_deg + (o.fov_up_deg - o.fov_down_deg) * b / (o.beams - 1)) *
            kDeg;
        shoot({std::cos(el) * std::cos(az), std::cos(el) * std::sin(az), std::sin(el)});
      }
    }
  } else {
    // Two prisms deflect the beam by a/2 each and turn at incommensurate rates: a rosette that drifts over
    // time, so the union of scans covers the cone densely.
    const double a = o.rosette_fov_deg * kDeg / 4;
    const double w1 = 2 * std::numbers::pi * 73.1, w2 = -2 * std::numbers::pi * 47.3;  // rad/s
    const double dt = 0.1 / o.rosette_points;
    for (int i = 0; i < o.rosette_points; ++i) {
      const double tau = t_pattern_s + i * dt;
      const double ay = a * (std::cos(w1 * tau) + std::cos(w2 * tau));
      const double az = a * (std::sin(w1 * tau) + std::sin(w2 * tau));
      shoot(Eigen::Vector3d(1, std::tan(ay), std::tan(az)).normalized());
    }
  }
  return scan;
}

LidarMaps accumulate_lidar_map(const std::vector<LidarScan>& scans,
                               const std::vector<Eigen::Isometry3d>& T_world_lidar, double voxel_m,
                               int holdout_every) {
  if (scans.size() != T_world_lidar.size())
    throw std::invalid_argument("accumulate_lidar_map: one pose per scan is needed");
  if (!(voxel_m > 0)) throw std::invalid_argument("accumulate_lidar_map: voxel_m must be > 0");
  struct KeyHash {
    size_t operator()(const Eigen::Vector3i& k) const {
      return static_cast<size_t>(
          hash_combine(hash_combine(static_cast<uint64_t>(k.x()), static_cast<uint64_t>(k.y())),
                       static_cast<uint64_t>(k.z())));
    }
  };
  size_t total = 0;
  for (const LidarScan& s : scans) total += s.points_lidar.size();
  std::unordered_map<Eigen::Vector3i, int, KeyHash> occupied;
  occupied.reserve(total / 2);
  LidarMaps maps;
  io::ScalarField plane{"plane_id", {}};
  for (size_t s = 0; s < scans.size(); ++s) {
    if (io::is_heldout_scan(s, holdout_every)) continue;
    for (size_t i = 0; i < scans[s].points_lidar.size(); ++i) {
      const Eigen::Vector3d p = T_world_lidar[s] * scans[s].points_lidar[i];
      // Voxel of the noisy point; the first point in insertion order wins, so the result is deterministic.
      const Eigen::Vector3i key = (p / voxel_m).array().floor().cast<int>();
      if (!occupied.emplace(key, 1).second) continue;
      maps.noisy.positions.push_back(p);
      maps.truth.positions.push_back(scans[s].true_world[i]);
      plane.values.push_back(scans[s].plane_id[i]);
    }
  }
  maps.truth.extra.push_back(std::move(plane));
  return maps;
}

}  // namespace litgs::host::synth
