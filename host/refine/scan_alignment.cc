#include "host/refine/scan_alignment.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <limits>
#include <memory>
#include <stdexcept>
#include <unordered_map>

#include "host/lidar_map/map_builder.h"
#include "host/train/point_kdtree.h"

namespace litgs::host::refine {

void ScanAlignmentOptions::check() const {
  if (map_points_per_scan < 1) throw std::invalid_argument("refine: scan map_points_per_scan must be >= 1");
  if (residual_points_per_scan < 1)
    throw std::invalid_argument("refine: scan residual_points_per_scan must be >= 1");
  if (!(voxel_m > 0) || !(voxel_start_m >= voxel_m))
    throw std::invalid_argument("refine: scan voxel_m must be > 0 and voxel_start_m >= voxel_m");
  if (!(search_radius_m > 0)) throw std::invalid_argument("refine: scan search_radius_m must be > 0");
  if (!(gate_start_m > 0) || !(gate_floor_m > 0))
    throw std::invalid_argument("refine: scan gate_start_m and gate_floor_m must be > 0");
}

double ScanAlignmentOptions::voxel_at(size_t round) const {
  return std::max(voxel_m, voxel_start_m / std::pow(2.0, static_cast<double>(round)));
}

namespace {

Eigen::Isometry3d world_from_cam(const CameraPose& pose) {
  Eigen::Isometry3d T = Eigen::Isometry3d::Identity();
  T.linear() = pose.q_world_cam.toRotationMatrix();
  T.translation() = pose.p_world_cam;
  return T;
}

constexpr size_t kCandidates = 5;

size_t stride(size_t n, size_t wanted) {
  return std::max<size_t>(1, n / std::max<size_t>(1, wanted));
}

// Voxel centroids of the scans placed through the poses.
std::vector<Eigen::Vector3d> voxel_map(const std::vector<RefineScan>& scans,
                                       const std::vector<CameraPose>& poses, double voxel_m,
                                       const ScanAlignmentOptions& o) {
  struct Sum {
    Eigen::Vector3d xyz = Eigen::Vector3d::Zero();
    size_t n = 0;
  };
  std::unordered_map<uint64_t, Sum> voxels;
  for (const RefineScan& s : scans) {
    const Eigen::Isometry3d T = world_from_cam(poses[s.frame]) * s.T_cam_scan;
    const size_t step = stride(s.points_lidar.size(), o.map_points_per_scan);
    for (size_t i = 0; i < s.points_lidar.size(); i += step) {
      const Eigen::Vector3d w = T * s.points_lidar[i];
      if (!w.allFinite()) continue;
      Sum& v = voxels[voxel_key(w, voxel_m)];
      v.xyz += w;
      ++v.n;
    }
  }
  std::vector<std::pair<uint64_t, Eigen::Vector3d>> sorted;  // by key: the same poses give the same map
  sorted.reserve(voxels.size());
  for (const auto& [key, v] : voxels) sorted.emplace_back(key, v.xyz / static_cast<double>(v.n));
  std::sort(sorted.begin(), sorted.end(), [](const auto& a, const auto& b) { return a.first < b.first; });
  std::vector<Eigen::Vector3d> points;
  points.reserve(sorted.size());
  for (const auto& kv : sorted) points.push_back(kv.second);
  return points;
}

void check_frames(const std::vector<RefineScan>& scans, const std::vector<CameraPose>& poses) {
  for (const RefineScan& s : scans)
    if (s.frame >= poses.size())
      throw std::invalid_argument("refine: a scan is tied to frame " + std::to_string(s.frame) + " of " +
                                  std::to_string(poses.size()));
}

}  // namespace

PlanarMap scan_map(const std::vector<RefineScan>& scans, const std::vector<CameraPose>& poses, size_t round,
                   const ScanAlignmentOptions& o) {
  o.check();
  check_frames(scans, poses);
  return fit_planes(voxel_map(scans, poses, o.voxel_at(round), o), {});
}

std::vector<ScanPlaneLink> associate_scan_planes(const std::vector<RefineScan>& scans,
                                                 const std::vector<CameraPose>& poses, size_t round,
                                                 const ScanAlignmentOptions& o,
                                                 ScanAssociationReport& report) {
  return associate_scan_planes(scans, poses, scan_map(scans, poses, round, o), round, o, report);
}

std::vector<ScanPlaneLink> associate_scan_planes(const std::vector<RefineScan>& scans,
                                                 const std::vector<CameraPose>& poses, const PlanarMap& map,
                                                 size_t round, const ScanAlignmentOptions& o,
                                                 ScanAssociationReport& report) {
  o.check();
  check_frames(scans, poses);
  report = {};
  report.gate_m = std::max(o.gate_floor_m, o.gate_start_m / std::pow(2.0, static_cast<double>(round)));
  std::vector<ScanPlaneLink> links;
  if (scans.empty()) return links;
  report.scans = scans.size();
  report.map_points = map.points.size();
  std::vector<Eigen::Vector3d> planar;
  std::vector<size_t> index;
  for (size_t i = 0; i < map.points.size(); ++i)
    if (map.planar[i]) {
      planar.push_back(map.points[i].cast<double>());
      index.push_back(i);
    }
  report.planar_map_points = planar.size();
  if (planar.empty()) return links;
  const PointCloudAdaptor adaptor{planar};
  PointKdTree tree(3, adaptor);
  tree.buildIndex();
  const double radius = std::max(o.search_radius_m, 2 * o.voxel_at(round));
  const double r2 = radius * radius;
  for (const RefineScan& s : scans) {
    const Eigen::Isometry3d T = world_from_cam(poses[s.frame]) * s.T_cam_scan;
    const size_t step = stride(s.points_lidar.size(), o.residual_points_per_scan);
    for (size_t i = 0; i < s.points_lidar.size(); i += step) {
      const Eigen::Vector3d x_cam = s.T_cam_scan * s.points_lidar[i];
      const Eigen::Vector3d w = T * s.points_lidar[i];
      if (!w.allFinite()) continue;
      // Of the nearest planar map points, the plane the point lies closest to: near an edge the nearest
      // point may belong to the other surface.
      std::array<uint32_t, kCandidates> nearest{};
      std::array<double, kCandidates> d2{};
      const size_t found = tree.knnSearch(w.data(), kCandidates, nearest.data(), d2.data());
      double best = std::numeric_limits<double>::infinity();
      PlaneRef plane;
      for (size_t k = 0; k < found; ++k) {
        if (d2[k] > r2) break;
        const size_t m = index[nearest[k]];
        const PlaneRef candidate{map.normals[m].cast<double>(), map.centres[m].cast<double>()};
        const double d = std::abs(candidate.n.dot(w - candidate.l));
        if (d < best) {
          best = d;
          plane = candidate;
        }
      }
      if (!(best <= report.gate_m)) continue;
      links.push_back({s.frame, x_cam, plane});
    }
  }
  report.links = links.size();
  return links;
}

double scan_plane_rms_m(const std::vector<ScanPlaneLink>& links, const std::vector<CameraPose>& poses) {
  if (links.empty()) return 0;
  double sum2 = 0;
  for (const ScanPlaneLink& l : links) {
    const Eigen::Vector3d w = poses[l.frame].q_world_cam * l.x_cam + poses[l.frame].p_world_cam;
    const double d = l.plane.n.dot(w - l.plane.l);
    sum2 += d * d;
  }
  return std::sqrt(sum2 / static_cast<double>(links.size()));
}

}  // namespace litgs::host::refine
