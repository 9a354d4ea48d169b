#include "host/train/lidar_planes.h"

#include <Eigen/Eigenvalues>
#include <algorithm>
#include <cmath>
#include <limits>
#include <nanoflann.hpp>
#include <stdexcept>

#include "host/train/point_kdtree.h"
#include "io/robust_stats.h"

namespace litgs::host {

void PlaneFitOptions::check() const {
  if (neighbours < 3) throw std::invalid_argument("PlaneFitOptions.neighbours must be >= 3");
  if (!(max_flatness > 0)) throw std::invalid_argument("PlaneFitOptions.max_flatness must be > 0");
  if (!(max_radius_m > 0)) throw std::invalid_argument("PlaneFitOptions.max_radius_m must be > 0");
}

size_t PlanarMap::planar_count() const {
  size_t n = 0;
  for (uint8_t p : planar) n += p;
  return n;
}

PlanarMap fit_planes(const std::vector<Eigen::Vector3d>& points, const PlaneFitOptions& o) {
  o.check();
  PlanarMap map;
  map.points.reserve(points.size());
  for (const auto& p : points) map.points.push_back(p.cast<float>());
  map.normals.assign(points.size(), Eigen::Vector3f::Zero());
  map.centres.assign(points.size(), Eigen::Vector3f::Zero());
  map.planar.assign(points.size(), 0);
  map.flatness.assign(points.size(), std::numeric_limits<float>::quiet_NaN());
  if (points.size() < o.neighbours) return map;
  PointCloudAdaptor adaptor{points};
  PointKdTree tree(3, adaptor, nanoflann::KDTreeSingleIndexAdaptorParams(10));
  tree.buildIndex();
  std::vector<uint32_t> idx(o.neighbours);
  std::vector<double> d2(o.neighbours);
  const double max_d2 = o.max_radius_m * o.max_radius_m;
  for (size_t i = 0; i < points.size(); ++i) {
    const size_t found = tree.knnSearch(points[i].data(), o.neighbours, idx.data(), d2.data());
    if (found < o.neighbours || d2[found - 1] > max_d2) continue;
    Eigen::Vector3d mean = Eigen::Vector3d::Zero();
    for (size_t j = 0; j < found; ++j) mean += points[idx[j]];
    mean /= static_cast<double>(found);
    Eigen::Matrix3d cov = Eigen::Matrix3d::Zero();
    for (size_t j = 0; j < found; ++j) {
      const Eigen::Vector3d d = points[idx[j]] - mean;
      cov += d * d.transpose();
    }
    const Eigen::SelfAdjointEigenSolver<Eigen::Matrix3d> eig(cov);
    const Eigen::Vector3d ev = eig.eigenvalues();  // ascending
    if (!(ev[1] > 0)) continue;
    map.flatness[i] = static_cast<float>(ev[0] / ev[1]);
    if (ev[0] / ev[1] > o.max_flatness) continue;
    map.normals[i] = eig.eigenvectors().col(0).cast<float>().normalized();
    map.centres[i] = mean.cast<float>();
    map.planar[i] = 1;
  }
  assign_surfel_radii(map, o.neighbours);
  return map;
}

void assign_surfel_radii(PlanarMap& map, uint32_t neighbours, double coverage) {
  if (neighbours < 1) throw std::invalid_argument("assign_surfel_radii: neighbours must be >= 1");
  if (!(coverage > 0)) throw std::invalid_argument("assign_surfel_radii: coverage must be > 0");
  map.radii.assign(map.points.size(), 0.0f);
  if (map.points.size() <= neighbours) return;
  std::vector<Eigen::Vector3d> pts;
  pts.reserve(map.points.size());
  for (const auto& p : map.points) pts.push_back(p.cast<double>());
  PointCloudAdaptor adaptor{pts};
  PointKdTree tree(3, adaptor, nanoflann::KDTreeSingleIndexAdaptorParams(10));
  tree.buildIndex();
  std::vector<uint32_t> idx(neighbours + 1);
  std::vector<double> d2(neighbours + 1);
  const double per_neighbour = coverage / std::sqrt(static_cast<double>(neighbours));
  for (size_t i = 0; i < pts.size(); ++i) {
    const size_t found =
        tree.knnSearch(pts[i].data(), neighbours + 1, idx.data(), d2.data());  // itself first
    if (found == neighbours + 1) map.radii[i] = static_cast<float>(std::sqrt(d2[neighbours]) * per_neighbour);
  }
}

ViewPlaneMaps project_planes(const PlanarMap& map, const kernels::SplatCamera& c, double max_radius_px) {
  const size_t W = c.width, H = c.height;
  ViewPlaneMaps out;
  out.points.assign(W * H * 4, 0.0f);
  out.normals.assign(W * H * 4, 0.0f);
  std::vector<double> zbuf(W * H, std::numeric_limits<double>::infinity());
  std::vector<int64_t> owner(W * H, -1);
  const bool discs = map.radii.size() == map.points.size();
  auto ray = [&](double px, double py) { return glm::dvec3((px - c.cx) / c.fx, (py - c.cy) / c.fy, 1.0); };
  auto claim = [&](size_t pix, double z, size_t i) {
    if (z < zbuf[pix]) {
      zbuf[pix] = z;
      owner[pix] = static_cast<int64_t>(i);
    }
  };
  // Every point takes part in the z-buffer (a non-planar point in front hides the plane behind it); only
  // pixels whose nearest surface is planar carry an entry.
  auto on_plane = [&](size_t i) -> Eigen::Vector3f {
    if (!map.planar[i]) return map.points[i];
    const Eigen::Vector3f& n = map.normals[i];
    return map.points[i] - n * n.dot(map.points[i] - map.centres[i]);
  };
  for (size_t i = 0; i < map.points.size(); ++i) {
    const Eigen::Vector3f p = on_plane(i);
    const glm::dvec3 q = c.R_cam_world * glm::dvec3(p.x(), p.y(), p.z()) + c.t_cam_world;
    if (q.z <= c.near_m) continue;
    const double u = c.fx * q.x / q.z + c.cx, v = c.fy * q.y / q.z + c.cy;
    const double r = discs ? map.radii[i] : 0.0;
    if (r <= 0 || q.z <= r + c.near_m) {  // a point: the pixel it falls in
      if (u >= 0 && v >= 0 && u < static_cast<double>(W) && v < static_cast<double>(H))
        claim(static_cast<size_t>(v) * W + static_cast<size_t>(u), q.z, i);
      continue;
    }
    // The disc's image lies within r / (z - r) of the centre's ray (normalized coordinates).
    const double reach = std::min(max_radius_px, c.fx * r / (q.z - r));
    const long x0 = std::max(0L, static_cast<long>(std::floor(u - reach))),
               x1 = std::min(static_cast<long>(W) - 1, static_cast<long>(std::floor(u + reach)));
    const long y0 = std::max(0L, static_cast<long>(std::floor(v - reach))),
               y1 = std::min(static_cast<long>(H) - 1, static_cast<long>(std::floor(v + reach)));
    if (x0 > x1 || y0 > y1) continue;
    if (map.planar[i]) {
      const Eigen::Vector3f& n = map.normals[i];
      const glm::dvec3 nc = c.R_cam_world * glm::dvec3(n.x(), n.y(), n.z());
      for (long y = y0; y <= y1; ++y)
        for (long x = x0; x <= x1; ++x) {
          const glm::dvec3 d = ray(static_cast<double>(x) + 0.5, static_cast<double>(y) + 0.5);
          const double denom = glm::dot(nc, d);
          if (std::abs(denom) < 1e-9) continue;  // the ray runs along the disc
          const double z = glm::dot(nc, q) / denom;
          if (z <= c.near_m || glm::length(z * d - q) > r) continue;
          claim(static_cast<size_t>(y) * W + static_cast<size_t>(x), z, i);
        }
    } else {
      const double r2_px = (c.fx * r / q.z) * (c.fx * r / q.z);
      for (long y = y0; y <= y1; ++y)
        for (long x = x0; x <= x1; ++x) {
          const double dx = static_cast<double>(x) + 0.5 - u, dy = static_cast<double>(y) + 0.5 - v;
          if (dx * dx + dy * dy <= r2_px) claim(static_cast<size_t>(y) * W + static_cast<size_t>(x), q.z, i);
        }
    }
  }
  for (size_t pix = 0; pix < W * H; ++pix) {
    if (owner[pix] < 0 || !map.planar[static_cast<size_t>(owner[pix])]) continue;
    const size_t i = static_cast<size_t>(owner[pix]);
    const Eigen::Vector3f& n = map.normals[i];
    const Eigen::Vector3f p = on_plane(i);
    const glm::dvec3 q = c.R_cam_world * glm::dvec3(p.x(), p.y(), p.z()) + c.t_cam_world;
    const glm::dvec3 nc = c.R_cam_world * glm::dvec3(n.x(), n.y(), n.z());
    for (int a = 0; a < 3; ++a) {
      out.points[4 * pix + a] = static_cast<float>(q[a]);
      out.normals[4 * pix + a] = static_cast<float>(nc[a]);
    }
    out.points[4 * pix + 3] = 1.0f;
    ++out.valid_count;
  }
  return out;
}

}  // namespace litgs::host

namespace litgs::host {
namespace {

struct FloatAdaptor {
  const std::vector<Eigen::Vector3f>* pts;
  size_t kdtree_get_point_count() const { return pts->size(); }
  float kdtree_get_pt(size_t i, size_t d) const { return (*pts)[i][static_cast<int>(d)]; }
  template <class B>
  bool kdtree_get_bbox(B&) const {
    return false;
  }
};
using FloatTree =
    nanoflann::KDTreeSingleIndexAdaptor<nanoflann::L2_Simple_Adaptor<float, FloatAdaptor>, FloatAdaptor, 3>;

}  // namespace

struct PlaneDistance::Index {
  std::vector<Eigen::Vector3f> points, normals, centres;
  std::vector<bool> planar;
  FloatAdaptor adaptor{&points};
  std::unique_ptr<FloatTree> tree;
  float max_d2 = 0;
};

PlaneDistance::PlaneDistance(const PlanarMap& map, double max_radius_m) : index_(std::make_unique<Index>()) {
  for (size_t i = 0; i < map.points.size(); ++i) {
    index_->points.push_back(map.points[i]);
    index_->normals.push_back(map.normals[i]);
    index_->centres.push_back(map.centres[i]);
    index_->planar.push_back(map.planar[i]);
  }
  index_->max_d2 = static_cast<float>(max_radius_m * max_radius_m);
  index_->tree =
      std::make_unique<FloatTree>(3, index_->adaptor, nanoflann::KDTreeSingleIndexAdaptorParams(10));
  if (!index_->points.empty()) index_->tree->buildIndex();
}

PlaneDistance::~PlaneDistance() = default;

std::vector<float> PlaneDistance::distances(const std::vector<float>& means) const {
  const size_t n = means.size() / 3;
  std::vector<float> out(n, std::numeric_limits<float>::quiet_NaN());
  if (index_->points.empty()) return out;
  for (size_t i = 0; i < n; ++i) {
    const Eigen::Vector3f x(means[3 * i], means[3 * i + 1], means[3 * i + 2]);
    if (!x.allFinite()) continue;
    uint32_t idx = 0;
    float d2 = 0;
    if (index_->tree->knnSearch(x.data(), 1, &idx, &d2) == 1 && d2 <= index_->max_d2 && index_->planar[idx])
      out[i] = std::abs(index_->normals[idx].dot(x - index_->centres[idx]));
  }
  return out;
}

float PlaneDistance::robust_bound(const std::vector<float>& d, double k, double floor_m) {
  std::vector<double> v;
  for (float x : d)
    if (std::isfinite(x)) v.push_back(x);
  if (v.empty()) return std::numeric_limits<float>::infinity();
  return static_cast<float>(io::robust_upper_bound(v, k, floor_m));
}

}  // namespace litgs::host
