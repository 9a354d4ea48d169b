// The part of a scene the training views observe, so that geometry is scored where the model could learn
// it. A point is observed when some training view sees it: it projects inside the image, in front of the
// camera, and no nearer than the view's first surface there allows, the first surface being the nearest
// reference point in the point's z-buffer cell, plus a margin. The same test selects the reference points
// and the Gaussians, so a floater in front of a seen surface counts against the model and a Gaussian
// behind every seen surface (never rendered in front of anything) does not.
//
// Approximate: a z-buffer of a point cloud in coarse cells lets a point show through where a cell's nearer
// surface has no sample, and hides the far side of a depth edge inside one cell.
#pragma once

#include <Eigen/Core>
#include <cstdint>
#include <vector>

#include "kernels/splat/splat_types.h"

namespace litgs::host {

struct ObservedRegionOptions {
  uint32_t cell_px = 8;                 // z-buffer cell edge, pixels of the training resolution
  double depth_margin_m = 0.10;         // how far behind a cell's first surface still counts as seen
  double depth_margin_fraction = 0.02;  // plus this share of the depth (noise grows with range)
  double coverage_radius_m = 0.10;      // a reference point is covered by a Gaussian centre this near
  double coverage_min_opacity = 0.1;    // Gaussians fainter than this do not cover
  void check() const;                   // std::invalid_argument naming the bad field
};

class ObservedRegion {
 public:
  // `reference`: the cloud whose first surfaces bound each view (world frame, as the cameras).
  ObservedRegion(const std::vector<Eigen::Vector3d>& reference,
                 const std::vector<kernels::SplatCamera>& views, const ObservedRegionOptions& options);
  bool contains(const Eigen::Vector3d& x) const;

 private:
  struct View {
    kernels::SplatCamera camera;
    uint32_t cells_x = 0, cells_y = 0;
    std::vector<float> first_depth_m;  // [cells_y][cells_x], +inf where no reference point projects
  };
  // The cell of x in view v and its depth; false outside the image or behind the camera.
  bool project(const View& v, const Eigen::Vector3d& x, size_t& cell, double& depth) const;
  std::vector<View> views_;
  ObservedRegionOptions options_;
};

struct RegionCoverage {
  size_t reference_points = 0, reference_observed = 0;
  size_t gaussians = 0, gaussians_in_region = 0;
  size_t reference_covered = 0;  // observed reference points with a Gaussian centre within the radius
  double coverage_radius_m = 0, coverage_min_opacity = 0;
  double reference_observed_fraction() const;
  double covered_fraction() const;  // of the observed reference points
};

// Splits the reference and the Gaussian centres by the region and counts the coverage. `observed_reference`
// and `centres_in_region` receive the points inside (indices into the inputs).
RegionCoverage measure_region(const ObservedRegion& region, const std::vector<Eigen::Vector3d>& reference,
                              const std::vector<Eigen::Vector3d>& centres,
                              const std::vector<double>& opacities, const ObservedRegionOptions& options,
                              std::vector<size_t>& observed_reference,
                              std::vector<size_t>& centres_in_region);

}  // namespace litgs::host
