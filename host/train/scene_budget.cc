#include "host/train/scene_budget.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <stdexcept>

#include "host/train/point_kdtree.h"
#include "io/robust_stats.h"

namespace litgs::host {
namespace {

// Metres per pixel at `p` in the finest camera whose image `p` projects into; infinity if none.
double finest_footprint_m(const Eigen::Vector3d& p, const std::vector<kernels::SplatCamera>& cameras) {
  double best = std::numeric_limits<double>::infinity();
  for (const kernels::SplatCamera& c : cameras) {
    const glm::dvec3 q = c.R_cam_world * glm::dvec3(p.x(), p.y(), p.z()) + c.t_cam_world;
    if (!(q.z > c.near_m)) continue;
    const double u = c.fx * q.x / q.z + c.cx, v = c.fy * q.y / q.z + c.cy;
    if (u < 0 || v < 0 || u >= c.width || v >= c.height) continue;
    best = std::min(best, q.z / std::sqrt(c.fx * c.fy));
  }
  return best;
}

}  // namespace

void SceneBudgetOptions::check() const {
  auto bad = [](const std::string& what) { throw std::invalid_argument("SceneBudgetOptions." + what); };
  if (!(pixels_per_gaussian > 0) || !std::isfinite(pixels_per_gaussian))
    bad("pixels_per_gaussian must be finite and positive");
  if (neighbours == 0) bad("neighbours must be positive");
  if (!(outlier_mads > 0)) bad("outlier_mads must be positive");
  if (min_gaussians == 0 || min_gaussians > max_gaussians)
    bad("min_gaussians must be positive and at most max_gaussians");
}

std::vector<uint8_t> inside_any_view(const std::vector<Eigen::Vector3d>& points,
                                     const std::vector<kernels::SplatCamera>& cameras) {
  for (const kernels::SplatCamera& c : cameras) c.check();
  std::vector<uint8_t> inside(points.size(), 0);
  for (size_t i = 0; i < points.size(); ++i)
    inside[i] = points[i].allFinite() && std::isfinite(finest_footprint_m(points[i], cameras));
  return inside;
}

SceneBudget derive_scene_budget(const std::vector<Eigen::Vector3d>& points,
                                const std::vector<kernels::SplatCamera>& cameras,
                                const SceneBudgetOptions& o) {
  o.check();
  for (const kernels::SplatCamera& c : cameras) c.check();
  SceneBudget b;
  b.points = points.size();

  std::vector<Eigen::Vector3d> seen;
  std::vector<double> footprint;
  for (const Eigen::Vector3d& p : points) {
    if (!p.allFinite()) continue;
    const double f = finest_footprint_m(p, cameras);
    if (!std::isfinite(f)) continue;
    seen.push_back(p);
    footprint.push_back(f);
  }
  b.points_seen = seen.size();
  if (seen.empty())
    throw std::invalid_argument("scene budget: none of the " + std::to_string(points.size()) +
                                " points lies inside a training view: no surface to derive a budget from");
  b.median_footprint_m = io::median(footprint);

  // r_k of every seen point (itself is the first neighbour found). A lone point stands for one Gaussian.
  const size_t k = std::min<size_t>(o.neighbours, seen.size() - 1);
  std::vector<double> radius(seen.size(), 0.0);
  if (k > 0) {
    PointCloudAdaptor adaptor{seen};
    PointKdTree tree(3, adaptor, nanoflann::KDTreeSingleIndexAdaptorParams(10));
    tree.buildIndex();
    std::vector<uint32_t> idx(k + 1);
    std::vector<double> d2(k + 1);
    for (size_t i = 0; i < seen.size(); ++i) {
      const size_t found =
          tree.knnSearch(seen[i].data(), static_cast<uint32_t>(k + 1), idx.data(), d2.data());
      radius[i] = std::sqrt(d2[found - 1]);
    }
    const double limit = io::robust_upper_bound(radius, o.outlier_mads, 0.0);
    for (double& r : radius) r = std::min(r, limit);
  }

  for (size_t i = 0; i < seen.size(); ++i) {
    const double area = k > 0 ? M_PI * radius[i] * radius[i] / static_cast<double>(k)
                              : o.pixels_per_gaussian * footprint[i] * footprint[i];
    b.surface_m2 += area;
    b.surface_pixels += area / (footprint[i] * footprint[i]);
  }
  const double wanted = std::ceil(b.surface_pixels / o.pixels_per_gaussian);
  b.gaussians = static_cast<uint32_t>(
      std::clamp(wanted, static_cast<double>(o.min_gaussians), static_cast<double>(o.max_gaussians)));
  return b;
}

}  // namespace litgs::host
