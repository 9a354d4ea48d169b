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

namespace {

// Distances of world points to the plane of their nearest planar point of one map.
class PlaneDistances {
 public:
  PlaneDistances(const PlanarMap& map, double max_distance_m) : map_(&map), max_(max_distance_m) {
    for (size_t i = 0; i < map.points.size(); ++i)
      if (map.planar[i]) {
        cloud_.pts.push_back(map.points[i].cast<double>());
        index_.push_back(i);
      }
    if (!cloud_.pts.empty()) {
      tree_ = std::make_unique<Tree>(3, cloud_);
      tree_->buildIndex();
    }
  }
  bool empty() const { return cloud_.pts.empty(); }
  // NaN beyond the bound.
  double operator()(const Eigen::Vector3d& x) const {
    size_t nearest = 0;
    double d2 = 0;
    nanoflann::KNNResultSet<double> result(1);
    result.init(&nearest, &d2);
    tree_->findNeighbors(result, x.data(), nanoflann::SearchParams());
    if (d2 > max_ * max_) return NAN;
    const size_t m = index_[nearest];
    return std::abs(map_->normals[m].cast<double>().dot(x - map_->centres[m].cast<double>()));
  }

 private:
  const PlanarMap* map_;
  double max_;
  Cloud cloud_;
  std::vector<size_t> index_;  // planar map point -> its index in the map
  std::unique_ptr<Tree> tree_;
};

}  // namespace

ScanVerdict judge_on_scans(const PlanarMap& prior_map, const PlanarMap& refined_map,
                           const std::vector<CheckedScan>& scans, const ScanCheckOptions& o) {
  o.check();
  ScanVerdict v;
  const PlaneDistances prior_distance(prior_map, o.max_distance_m),
      refined_distance(refined_map, o.max_distance_m);
  if (prior_distance.empty() || refined_distance.empty() || scans.empty()) {
    v.summary = "held-out scans: none to compare (no planar map or no scans)";
    return v;
  }
  double sum_prior = 0, sum_refined = 0;
  for (const CheckedScan& s : scans) {
    if (s.points_lidar.empty()) continue;
    ++v.scans;
    const size_t step = std::max<size_t>(1, s.points_lidar.size() / o.points_per_scan);
    for (size_t k = 0; k < s.points_lidar.size(); k += step) {
      const Eigen::Vector4d x = s.points_lidar[k].homogeneous();
      const double dp = prior_distance((s.T_world_lidar_prior * x).head<3>());
      const double dr = refined_distance((s.T_world_lidar_refined * x).head<3>());
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
