// The synthetic world: textured rectangles (walls, ground, doors, window panes, box faces; optionally with
// rectangular or round holes) and vertical cylinders, with a brute-force ray caster. Every rectangle is one
// true plane of gt/planes.txt.
#pragma once

#include <Eigen/Core>
#include <optional>
#include <vector>

#include "host/synth/thermal_texture.h"
#include "io/scene_types.h"

namespace litgs::host::synth {

struct Ray {
  Eigen::Vector3d origin = Eigen::Vector3d::Zero();
  Eigen::Vector3d dir = Eigen::Vector3d::UnitX();  // unit length
};

// A rectangular hole in a rectangle's (u, v) coordinates (metres): a window or door opening.
struct Hole {
  double u0_m = 0, v0_m = 0, u1_m = 0, v1_m = 0;
};

// A round hole in a rectangle's (u, v) coordinates (metres): the extrinsic calibration board's.
struct RoundHole {
  double u_m = 0, v_m = 0, radius_m = 0;
};

// origin + u * u_axis + v * v_axis for u in [0, u_len_m], v in [0, v_len_m], minus the holes.
struct Rect {
  Eigen::Vector3d origin = Eigen::Vector3d::Zero();
  Eigen::Vector3d u_axis = Eigen::Vector3d::UnitX();  // unit
  Eigen::Vector3d v_axis = Eigen::Vector3d::UnitY();  // unit, orthogonal to u_axis
  double u_len_m = 1, v_len_m = 1;
  std::vector<Hole> holes;
  int texture = 0;  // index into World::textures
  std::vector<RoundHole> round_holes;
};

// A vertical cylinder (posts, pipes, columns): its side only.
struct Cylinder {
  Eigen::Vector2d center_xy = Eigen::Vector2d::Zero();
  double radius_m = 0.1;
  double z0_m = 0, z1_m = 1;
  int texture = 0;
};

struct Hit {
  double range_m = 0;                                 // along the ray
  Eigen::Vector3d point = Eigen::Vector3d::Zero();    // world
  Eigen::Vector3d normal = Eigen::Vector3d::UnitZ();  // unit, facing the ray's origin
  double u_m = 0, v_m = 0;                            // texture coordinates
  int texture = 0;
  int plane_id = -1;  // index of the rectangle (and of its plane in planes()); -1 for a cylinder
};

struct World {
  std::vector<Rect> rects;
  std::vector<Cylinder> cylinders;
  std::vector<ThermalTexture> textures;
  double sky_raw = 2900;  // raw counts of a ray that hits nothing (a cold sky)

  int add_texture(const ThermalTexture& t);
  // Adds a rectangle and returns its index (= its plane id).
  int add_rect(const Rect& r);
  // A box standing on z = z0_m: four sides and a top (no bottom: it is never seen). Size (x, y, z) before
  // the yaw about the vertical axis through its centre.
  void add_box(const Eigen::Vector3d& center_bottom, const Eigen::Vector3d& size_m, double yaw_rad,
               int texture);
  // A vertical wall from `start` along the horizontal unit `dir` (u) and up (v), with openings: each
  // opening gets a pane `recess_m` behind the wall (away from `normal_side`, a point in front of the wall),
  // a bit larger than the hole so oblique rays through it never see past the pane.
  struct Opening {
    Hole hole;
    double recess_m = 0.15;
    int texture = 0;
  };
  void add_wall(const Eigen::Vector3d& start, const Eigen::Vector3d& dir, double length_m, double height_m,
                int texture, const std::vector<Opening>& openings, const Eigen::Vector3d& front_point);

  // Builds the bounding-volume hierarchy that cast() walks; call after the last add_*. Without it (or after
  // a change) cast() tests every primitive: same hits, slower.
  void build_index();

  // The nearest hit with range in (min_m, max_m), if any.
  std::optional<Hit> cast(const Ray& ray, double min_m, double max_m) const;

  // Derived by build_index(): a BVH over the primitives (rects first, then cylinders).
  struct BvhNode {
    Eigen::Vector3d lo, hi;     // bounding box
    int left = -1, right = -1;  // children, or -1 for a leaf
    int first = 0, count = 0;   // a leaf's primitives: bvh_prims[first .. first + count)
  };
  std::vector<BvhNode> bvh_nodes;
  std::vector<int> bvh_prims;
  size_t bvh_rects = 0, bvh_cylinders = 0;  // the sizes the index was built for
  // One plane per rectangle, in rectangle order (plane_id indexes this).
  std::vector<io::Plane> planes() const;
};

}  // namespace litgs::host::synth
