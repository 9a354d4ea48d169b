// A nanoflann k-d tree over a vector of 3D points (the points are referenced, not copied: keep them alive
// and unchanged while the tree is used). Include only from .cc files: nanoflann is a large header.
#pragma once

#include <Eigen/Core>
#include <nanoflann.hpp>
#include <vector>

namespace litgs::host {

struct PointCloudAdaptor {
  const std::vector<Eigen::Vector3d>& pts;
  size_t kdtree_get_point_count() const { return pts.size(); }
  double kdtree_get_pt(size_t i, size_t dim) const { return pts[i][static_cast<int>(dim)]; }
  template <class B>
  bool kdtree_get_bbox(B&) const {
    return false;
  }
};

using PointKdTree =
    nanoflann::KDTreeSingleIndexAdaptor<nanoflann::L2_Simple_Adaptor<double, PointCloudAdaptor>,
                                        PointCloudAdaptor, 3>;

}  // namespace litgs::host
