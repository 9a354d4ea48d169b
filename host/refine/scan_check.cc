#include "host/refine/scan_check.h"

#include <Eigen/Geometry>
#include <cmath>
#include <cstdio>
#include <memory>
#include <nanoflann.hpp>
#include <stdexcept>

namespace litgs::host::refine {
namespace {

struct Cloud {
  std::vector<Eigen::Vector3d> pts;
  size_t kdtree_get_point_count() const { return pts.size(); }
  double kdtree_get_pt(size_t i, size_t d) const { return pts[i][static_cast<int>(d)]; }
  template <class B>
  bool kdtree_get_bbox(B&) const {
    return false;
  }
};
using Tree = nanoflann::KDTreeSingleIndexAdaptor<nanoflann::L2_Simple_Adaptor<double, Cloud>, Cloud, 3>;

}  // namespace

void ScanCheckOptions::check() const {
  if (every == 1) throw std::invalid_argument("refine: scan check every must be 0 (off) or >= 2");
  if (points_per_scan < 1) throw std::invalid_argument("refine: scan check points_per_scan must be >= 1");
  if (!(max_distance_m > 0)) throw std::invalid_argument("refine: scan check max_distance_m must be > 0");
  if (!(tolerance >= 0)) throw std::invalid_argument("refine: scan check tolerance must be >= 0");
}

ScanVerdict judge_on_scans(const PlanarMap& map, const std::vector<CheckedScan>& scans,
                           const ScanCheckOptions& o) {
  o.check();
  ScanVerdict v;
  Cloud cloud;
  std::vector<size_t> index;  // planar map point -> its index in the map
  for (size_t i = 0; i < map.points.size(); ++i)
    if (map.planar[i]) {
      cloud.pts.push_back(map.points[i].cast<double>());
      index.push_back(i);
    }
  if (cloud.pts.empty() || scans.empty()) {
    v.summary = "held-out scans: none to compare (no planar map or no scans)";
    return v;
  }
  Tree tree(3, cloud);
  tree.buildIndex();
  // Distance of a world point to the plane of its nearest planar map point; NaN beyond the bound.
  auto distance = [&](const Eigen::Vector3d& x) -> double {
    size_t nearest = 0;
    double d2 = 0;
    nanoflann::KNNResultSet<double> result(1);
    result.init(&nearest, &d2);
    tree.findNeighbors(result, x.data(), nanoflann::SearchParams());
    if (d2 > o.max_distance_m * o.max_distance_m) return NAN;
    const size_t m = index[nearest];
    return std::abs(map.normals[m].cast<double>().dot(x - map.centres[m].cast<double>()));
  };
  double sum_prior = 0, sum_refined = 0;
  for (const CheckedScan& s : scans) {
    if (s.points_lidar.empty()) continue;
    ++v.scans;
    const size_t step = std::max<size_t>(1, s.points_lidar.size() / o.points_per_scan);
    for (size_t k = 0; k < s.points_lidar.size(); k += step) {
      const Eigen::Vector4d x = s.points_lidar[k].homogeneous();
      const double dp = distance((s.T_world_lidar_prior * x).head<3>());
      const double dr = distance((s.T_world_lidar_refined * x).head<3>());
      if (!std::isfinite(dp) || !std::isfinite(dr) || dp > o.max_distance_m || dr > o.max_distance_m)
        continue;
      sum_prior += dp;
      sum_refined += dr;
      ++v.points;
    }
  }
  v.measured = v.points > 0;
  if (v.measured) {
    v.prior_mean_m = sum_prior / static_cast<double>(v.points);
    v.refined_mean_m = sum_refined / static_cast<double>(v.points);
    v.keep_refined = v.refined_mean_m <= (1 + o.tolerance) * v.prior_mean_m;
  }
  char text[320];
  std::snprintf(text, sizeof text,
                "held-out scans (%zu, %zu points): mean point-to-plane %.4f m through the priors, %.4f m "
                "through the refined poses%s",
                v.scans, v.points, v.prior_mean_m, v.refined_mean_m,
                !v.measured      ? ": no verdict"
                : v.keep_refined ? ""
                                 : ": worse");
  v.summary = text;
  return v;
}

}  // namespace litgs::host::refine
