// What the geometric loss needs from the LiDAR map: a plane normal per map point (local plane fit), and per
// view the nearest map point of each pixel with its normal, in the camera frame.
#pragma once

#include <Eigen/Core>
#include <cstdint>
#include <memory>
#include <vector>

#include "kernels/splat/splat_types.h"

namespace litgs::host {

struct PlaneFitOptions {
  uint32_t neighbours = 12;    // map points in each local plane fit
  double max_flatness = 0.05;  // smallest / middle eigenvalue of the neighbourhood: above it, not planar
  double max_radius_m = 1.0;   // neighbours farther than this make the fit invalid (sparse areas)
  void check() const;          // throws std::invalid_argument naming the bad field
};

// A LiDAR map with a local plane (a point on it and a unit normal) per point where its neighbourhood is
// planar. The plane point is the neighbourhood's centroid: the range noise along the normal averages down
// over the fit, where the raw point keeps all of it.
struct PlanarMap {
  std::vector<Eigen::Vector3f> points;   // world, metres (the scene's recentred frame)
  std::vector<Eigen::Vector3f> normals;  // unit, sign arbitrary (the loss squares the residual)
  std::vector<Eigen::Vector3f>
      centres;                  // the local plane's point (centroid of the fit); zero where not planar
  std::vector<uint8_t> planar;  // 1 where the fit is valid
  // Smallest / middle eigenvalue of each neighbourhood (0 on a perfect plane); NaN where no fit was made
  // (too few or too distant neighbours).
  std::vector<float> flatness;
  // The surface each point stands for in a view: a disc of this radius (metres; on its plane where planar,
  // facing the camera elsewhere), so that a nearer surface hides the points behind it between its own
  // sparse points. Empty or 0: the point covers only the pixel it falls in.
  std::vector<float> radii;
  size_t planar_count() const;
};

PlanarMap fit_planes(const std::vector<Eigen::Vector3d>& points, const PlaneFitOptions& options);

// radii of `map` from the local point density: R_k / sqrt(k) * coverage, R_k the distance to the k-th
// nearest other point, so that discs of the density's mean area (coverage 1) tile a uniform surface; the
// default overlaps them a little so that no gaps let farther points through.
void assign_surfel_radii(PlanarMap& map, uint32_t neighbours = 12, double coverage = 1.5);

// Per-pixel LiDAR point and normal of one view, the layout of the geometric loss kernel:
// points [H][W][4] = (x, y, z, valid) and normals [H][W][4] = (nx, ny, nz, 0), camera frame.
struct ViewPlaneMaps {
  std::vector<float> points;
  std::vector<float> normals;
  uint32_t valid_count = 0;
};

// The nearest map surface per pixel by a z-buffer of the points' discs (pixel centres at +0.5, the
// rasterizer's convention): a planar point's disc lies on its local plane and is depth-tested where the
// pixel's ray meets that plane; a non-planar point's faces the camera at its depth (it only hides what lies
// behind). Where the nearest disc is planar, the pixel carries its point moved onto the local plane, and the
// plane's normal. Points project with their radius clamped to max_radius_px pixels.
ViewPlaneMaps project_planes(const PlanarMap& map, const kernels::SplatCamera& camera,
                             double max_radius_px = 16);

}  // namespace litgs::host

namespace litgs::host {

// Distances of points to the LiDAR planes, for the densifier's geometric outlier prune: for each query, the
// nearest map point p (within max_radius_m) is its association; where p lies on a plane the distance is
// |n . (x - c)| to p's local plane (centroid c, normal n), where p is not planar (foliage, edges, clutter) or
// there is no point in reach it is NaN (no plane claims the query, so it is never pruned by distance).
class PlaneDistance {
 public:
  explicit PlaneDistance(const PlanarMap& map, double max_radius_m = 0.5);
  ~PlaneDistance();
  std::vector<float> distances(const std::vector<float>& means_xyz) const;  // means: [N][3]
  // A robust bound on distances: median + k * 1.4826 * MAD of the finite ones, at least floor_m.
  static float robust_bound(const std::vector<float>& distances, double k = 5.0, double floor_m = 0.1);

 private:
  struct Index;
  std::unique_ptr<Index> index_;
};

}  // namespace litgs::host
