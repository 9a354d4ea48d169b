#include "host/synth/geometry.h"

#include <algorithm>
#include <cmath>
#include <stdexcept>

namespace litgs::host::synth {

int World::add_texture(const ThermalTexture& t) {
  textures.push_back(t);
  return static_cast<int>(textures.size()) - 1;
}

int World::add_rect(const Rect& r) {
  if (std::abs(r.u_axis.norm() - 1) > 1e-9 || std::abs(r.v_axis.norm() - 1) > 1e-9 ||
      std::abs(r.u_axis.dot(r.v_axis)) > 1e-9)
    throw std::invalid_argument("World::add_rect: u_axis and v_axis must be orthonormal");
  if (!(r.u_len_m > 0 && r.v_len_m > 0)) throw std::invalid_argument("World::add_rect: empty rectangle");
  rects.push_back(r);
  return static_cast<int>(rects.size()) - 1;
}

void World::add_box(const Eigen::Vector3d& c, const Eigen::Vector3d& size, double yaw, int texture) {
  const Eigen::Vector3d ex(std::cos(yaw), std::sin(yaw), 0), ey(-std::sin(yaw), std::cos(yaw), 0),
      ez = Eigen::Vector3d::UnitZ();
  const Eigen::Vector3d hx = ex * size.x() / 2, hy = ey * size.y() / 2;
  // Sides, each running counter-clockwise seen from above, then the top.
  add_rect({c - hx - hy, ex, ez, size.x(), size.z(), {}, texture});
  add_rect({c + hx - hy, ey, ez, size.y(), size.z(), {}, texture});
  add_rect({c + hx + hy, -ex, ez, size.x(), size.z(), {}, texture});
  add_rect({c - hx + hy, -ey, ez, size.y(), size.z(), {}, texture});
  add_rect({c - hx - hy + ez * size.z(), ex, ey, size.x(), size.y(), {}, texture});
}

void World::add_wall(const Eigen::Vector3d& start, const Eigen::Vector3d& dir, double length_m,
                     double height_m, int texture, const std::vector<Opening>& openings,
                     const Eigen::Vector3d& front_point) {
  Rect wall{start, dir.normalized(), Eigen::Vector3d::UnitZ(), length_m, height_m, {}, texture};
  Eigen::Vector3d normal = wall.u_axis.cross(wall.v_axis);
  if (normal.dot(front_point - start) < 0) normal = -normal;  // points to the front
  for (const Opening& o : openings) wall.holes.push_back(o.hole);
  add_rect(wall);
  for (const Opening& o : openings) {
    const double margin = 2 * o.recess_m;  // hides the pane's edge up to ~63 degrees of incidence
    const double u0 = std::max(0.0, o.hole.u0_m - margin), v0 = std::max(0.0, o.hole.v0_m - margin);
    const double u1 = std::min(length_m, o.hole.u1_m + margin), v1 = std::min(height_m, o.hole.v1_m + margin);
    add_rect({start + wall.u_axis * u0 + wall.v_axis * v0 - normal * o.recess_m,
              wall.u_axis,
              wall.v_axis,
              u1 - u0,
              v1 - v0,
              {},
              o.texture});
  }
}

namespace {

// Intersects rectangle i; on a nearer hit than best_t, updates best_t and hit.
void cast_rect(const Rect& r, int i, const Ray& ray, double min_m, double& best_t, std::optional<Hit>& best) {
  const Eigen::Vector3d n = r.u_axis.cross(r.v_axis);
  const double denom = n.dot(ray.dir);
  if (std::abs(denom) < 1e-12) return;
  const double t = n.dot(r.origin - ray.origin) / denom;
  if (!(t > min_m && t < best_t)) return;
  const Eigen::Vector3d rel = ray.origin + t * ray.dir - r.origin;
  const double u = rel.dot(r.u_axis), v = rel.dot(r.v_axis);
  if (u < 0 || u > r.u_len_m || v < 0 || v > r.v_len_m) return;
  for (const Hole& h : r.holes)
    if (u > h.u0_m && u < h.u1_m && v > h.v0_m && v < h.v1_m) return;
  for (const RoundHole& h : r.round_holes)
    if ((u - h.u_m) * (u - h.u_m) + (v - h.v_m) * (v - h.v_m) < h.radius_m * h.radius_m) return;
  best_t = t;
  best = Hit{t, ray.origin + t * ray.dir, denom < 0 ? n : Eigen::Vector3d(-n), u, v, r.texture, i};
}

void cast_cylinder(const Cylinder& c, const Ray& ray, double min_m, double& best_t,
                   std::optional<Hit>& best) {
  // |o_xy + t d_xy - c|^2 = r^2, nearest root in range.
  const Eigen::Vector2d o = ray.origin.head<2>() - c.center_xy, d = ray.dir.head<2>();
  const double a = d.squaredNorm();
  if (a < 1e-12) return;
  const double b = o.dot(d), cc = o.squaredNorm() - c.radius_m * c.radius_m;
  const double disc = b * b - a * cc;
  if (disc < 0) return;
  const double sq = std::sqrt(disc);
  for (const double t : {(-b - sq) / a, (-b + sq) / a}) {
    if (!(t > min_m && t < best_t)) continue;
    const Eigen::Vector3d p = ray.origin + t * ray.dir;
    if (p.z() < c.z0_m || p.z() > c.z1_m) continue;
    Eigen::Vector3d n(p.x() - c.center_xy.x(), p.y() - c.center_xy.y(), 0);
    n.normalize();
    if (n.dot(ray.dir) > 0) n = -n;
    const double angle = std::atan2(p.y() - c.center_xy.y(), p.x() - c.center_xy.x());
    best_t = t;
    best = Hit{t, p, n, angle * c.radius_m, p.z() - c.z0_m, c.texture, -1};
    return;
  }
}

// Slab test: does the ray enter [lo, hi] before best_t?
bool hits_box(const Eigen::Vector3d& lo, const Eigen::Vector3d& hi, const Ray& ray,
              const Eigen::Vector3d& inv, double min_m, double best_t) {
  double t0 = min_m, t1 = best_t;
  for (int k = 0; k < 3; ++k) {
    double a = (lo[k] - ray.origin[k]) * inv[k], b = (hi[k] - ray.origin[k]) * inv[k];
    if (a > b) std::swap(a, b);
    t0 = std::max(t0, a);
    t1 = std::min(t1, b);
    if (t0 > t1) return false;
  }
  return true;
}

}  // namespace

void World::build_index() {
  struct Item {
    Eigen::Vector3d lo, hi, centre;
    int prim;
  };
  std::vector<Item> items;
  const double pad = 1e-6;  // axis-aligned rectangles have zero thickness
  for (size_t i = 0; i < rects.size(); ++i) {
    const Rect& r = rects[i];
    Eigen::Vector3d lo = r.origin, hi = r.origin;
    for (const Eigen::Vector3d& c :
         {Eigen::Vector3d(r.origin + r.u_axis * r.u_len_m), Eigen::Vector3d(r.origin + r.v_axis * r.v_len_m),
          Eigen::Vector3d(r.origin + r.u_axis * r.u_len_m + r.v_axis * r.v_len_m)}) {
      lo = lo.cwiseMin(c);
      hi = hi.cwiseMax(c);
    }
    items.push_back({lo.array() - pad, hi.array() + pad, (lo + hi) / 2, static_cast<int>(i)});
  }
  for (size_t i = 0; i < cylinders.size(); ++i) {
    const Cylinder& c = cylinders[i];
    const Eigen::Vector3d lo(c.center_xy.x() - c.radius_m, c.center_xy.y() - c.radius_m, c.z0_m),
        hi(c.center_xy.x() + c.radius_m, c.center_xy.y() + c.radius_m, c.z1_m);
    items.push_back({lo, hi, (lo + hi) / 2, static_cast<int>(rects.size() + i)});
  }
  bvh_nodes.clear();
  bvh_prims.clear();
  // Median split on the widest axis of the centres, two primitives per leaf.
  auto build = [&](auto&& self, int first, int count) -> int {
    BvhNode node;
    node.lo = Eigen::Vector3d::Constant(1e300);
    node.hi = Eigen::Vector3d::Constant(-1e300);
    Eigen::Vector3d clo = node.lo, chi = node.hi;
    for (int i = first; i < first + count; ++i) {
      node.lo = node.lo.cwiseMin(items[i].lo);
      node.hi = node.hi.cwiseMax(items[i].hi);
      clo = clo.cwiseMin(items[i].centre);
      chi = chi.cwiseMax(items[i].centre);
    }
    const int index = static_cast<int>(bvh_nodes.size());
    bvh_nodes.push_back(node);
    if (count <= 2) {
      bvh_nodes[index].first = static_cast<int>(bvh_prims.size());
      bvh_nodes[index].count = count;
      for (int i = first; i < first + count; ++i) bvh_prims.push_back(items[i].prim);
      return index;
    }
    int axis = 0;
    (chi - clo).maxCoeff(&axis);
    const int half = count / 2;
    std::nth_element(items.begin() + first, items.begin() + first + half, items.begin() + first + count,
                     [axis](const Item& a, const Item& b) {
                       return a.centre[axis] < b.centre[axis] ||
                              (a.centre[axis] == b.centre[axis] && a.prim < b.prim);
                     });
    const int left = self(self, first, half);
    const int right = self(self, first + half, count - half);
    bvh_nodes[index].left = left;
    bvh_nodes[index].right = right;
    return index;
  };
  if (!items.empty()) build(build, 0, static_cast<int>(items.size()));
  bvh_rects = rects.size();
  bvh_cylinders = cylinders.size();
}

std::optional<Hit> World::cast(const Ray& ray, double min_m, double max_m) const {
  std::optional<Hit> best;
  double best_t = max_m;
  const int n_rects = static_cast<int>(rects.size());
  auto test = [&](int prim) {
    if (prim < n_rects)
      cast_rect(rects[prim], prim, ray, min_m, best_t, best);
    else
      cast_cylinder(cylinders[prim - n_rects], ray, min_m, best_t, best);
  };
  if (bvh_nodes.empty() || bvh_rects != rects.size() || bvh_cylinders != cylinders.size()) {
    for (int i = 0; i < n_rects + static_cast<int>(cylinders.size()); ++i) test(i);
    return best;
  }
  // Ties between primitives at the same range resolve by visiting order; both orders are deterministic.
  const Eigen::Vector3d inv = ray.dir.cwiseInverse();
  int stack[64];
  int top = 0;
  stack[top++] = 0;
  while (top > 0) {
    const BvhNode& node = bvh_nodes[stack[--top]];
    if (!hits_box(node.lo, node.hi, ray, inv, min_m, best_t)) continue;
    if (node.left < 0) {
      for (int k = 0; k < node.count; ++k) test(bvh_prims[node.first + k]);
    } else {
      stack[top++] = node.right;
      stack[top++] = node.left;
    }
  }
  return best;
}

std::vector<io::Plane> World::planes() const {
  std::vector<io::Plane> out;
  out.reserve(rects.size());
  for (const Rect& r : rects) {
    const Eigen::Vector3d n = r.u_axis.cross(r.v_axis).normalized();
    out.push_back({n, -n.dot(r.origin)});
  }
  return out;
}

}  // namespace litgs::host::synth
