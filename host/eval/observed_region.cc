#include "host/eval/observed_region.h"

#include <cmath>
#include <limits>
#include <stdexcept>
#include <unordered_map>

namespace litgs::host {
namespace {

// A hash of the cells of a uniform grid (edge = the coverage radius) holding point indices.
struct PointGrid {
  double cell = 1;
  std::unordered_map<uint64_t, std::vector<size_t>> cells;

  static uint64_t key(int64_t x, int64_t y, int64_t z) {
    constexpr int64_t kHalf = int64_t{1} << 20;
    auto part = [](int64_t c) { return static_cast<uint64_t>(c + kHalf) & ((uint64_t{1} << 21) - 1); };
    return (part(x) << 42) | (part(y) << 21) | part(z);
  }
  Eigen::Vector3i index(const Eigen::Vector3d& p) const {
    return {static_cast<int>(std::floor(p.x() / cell)), static_cast<int>(std::floor(p.y() / cell)),
            static_cast<int>(std::floor(p.z() / cell))};
  }
  void add(const Eigen::Vector3d& p, size_t i) {
    const Eigen::Vector3i c = index(p);
    cells[key(c.x(), c.y(), c.z())].push_back(i);
  }
};

}  // namespace

void ObservedRegionOptions::check() const {
  if (cell_px < 1) throw std::invalid_argument("observed region: cell_px must be >= 1");
  if (!(depth_margin_m >= 0) || !(depth_margin_fraction >= 0))
    throw std::invalid_argument("observed region: the depth margins must be >= 0");
  if (!(coverage_radius_m > 0)) throw std::invalid_argument("observed region: coverage_radius_m must be > 0");
  if (!(coverage_min_opacity >= 0 && coverage_min_opacity <= 1))
    throw std::invalid_argument("observed region: coverage_min_opacity must be in [0, 1]");
}

ObservedRegion::ObservedRegion(const std::vector<Eigen::Vector3d>& reference,
                               const std::vector<kernels::SplatCamera>& cameras,
                               const ObservedRegionOptions& options)
    : options_(options) {
  options.check();
  for (const kernels::SplatCamera& camera : cameras) {
    View v;
    v.camera = camera;
    v.cells_x = (camera.width + options.cell_px - 1) / options.cell_px;
    v.cells_y = (camera.height + options.cell_px - 1) / options.cell_px;
    v.first_depth_m.assign(size_t{v.cells_x} * v.cells_y, std::numeric_limits<float>::infinity());
    for (const Eigen::Vector3d& x : reference) {
      size_t cell = 0;
      double depth = 0;
      if (project(v, x, cell, depth) && depth < v.first_depth_m[cell])
        v.first_depth_m[cell] = static_cast<float>(depth);
    }
    views_.push_back(std::move(v));
  }
}

bool ObservedRegion::project(const View& v, const Eigen::Vector3d& x, size_t& cell, double& depth) const {
  const kernels::SplatCamera& c = v.camera;
  const glm::dvec3 p = c.R_cam_world * glm::dvec3(x.x(), x.y(), x.z()) + c.t_cam_world;
  if (!(p.z > c.near_m)) return false;
  // Pixel i spans [i, i + 1) (its centre at i + 0.5, splat_types.h).
  const double u = c.fx * p.x / p.z + c.cx, w = c.fy * p.y / p.z + c.cy;
  if (!(u >= 0 && u < c.width && w >= 0 && w < c.height)) return false;
  cell = static_cast<size_t>(w / options_.cell_px) * v.cells_x + static_cast<size_t>(u / options_.cell_px);
  depth = p.z;
  return true;
}

bool ObservedRegion::contains(const Eigen::Vector3d& x) const {
  for (const View& v : views_) {
    size_t cell = 0;
    double depth = 0;
    if (!project(v, x, cell, depth)) continue;
    const double first = v.first_depth_m[cell];
    if (std::isfinite(first) &&
        depth <= first + options_.depth_margin_m + options_.depth_margin_fraction * first)
      return true;
  }
  return false;
}

double RegionCoverage::reference_observed_fraction() const {
  return reference_points ? static_cast<double>(reference_observed) / static_cast<double>(reference_points)
                          : 0.0;
}

double RegionCoverage::covered_fraction() const {
  return reference_observed ? static_cast<double>(reference_covered) / static_cast<double>(reference_observed)
                            : 0.0;
}

RegionCoverage measure_region(const ObservedRegion& region, const std::vector<Eigen::Vector3d>& reference,
                              const std::vector<Eigen::Vector3d>& centres,
                              const std::vector<double>& opacities, const ObservedRegionOptions& o,
                              std::vector<size_t>& observed_reference,
                              std::vector<size_t>& centres_in_region) {
  o.check();
  if (opacities.size() != centres.size())
    throw std::invalid_argument("measure_region: one opacity per Gaussian centre is needed");
  RegionCoverage c;
  c.reference_points = reference.size();
  c.gaussians = centres.size();
  c.coverage_radius_m = o.coverage_radius_m;
  c.coverage_min_opacity = o.coverage_min_opacity;
  observed_reference.clear();
  centres_in_region.clear();
  for (size_t i = 0; i < reference.size(); ++i)
    if (region.contains(reference[i])) observed_reference.push_back(i);
  PointGrid grid;
  grid.cell = o.coverage_radius_m;
  for (size_t g = 0; g < centres.size(); ++g) {
    if (!region.contains(centres[g])) continue;
    centres_in_region.push_back(g);
    if (opacities[g] >= o.coverage_min_opacity) grid.add(centres[g], g);
  }
  c.reference_observed = observed_reference.size();
  c.gaussians_in_region = centres_in_region.size();
  const double r2 = o.coverage_radius_m * o.coverage_radius_m;
  for (size_t i : observed_reference) {
    const Eigen::Vector3i k = grid.index(reference[i]);
    bool covered = false;
    for (int dx = -1; dx <= 1 && !covered; ++dx)
      for (int dy = -1; dy <= 1 && !covered; ++dy)
        for (int dz = -1; dz <= 1 && !covered; ++dz) {
          const auto it = grid.cells.find(PointGrid::key(k.x() + dx, k.y() + dy, k.z() + dz));
          if (it == grid.cells.end()) continue;
          for (size_t g : it->second)
            if ((centres[g] - reference[i]).squaredNorm() <= r2) {
              covered = true;
              break;
            }
        }
    if (covered) ++c.reference_covered;
  }
  return c;
}

}  // namespace litgs::host
