// Multi-view triangulation of one track from known poses: the least-squares midpoint of the viewing rays,
// made robust by trying pairs of views and keeping the largest set that reprojects within a bound.
#pragma once

#include <optional>
#include <vector>

#include "host/refine/ba_types.h"

namespace litgs::host::refine {

struct TriangulationOptions {
  double inlier_px = 4;        // reprojection bound of the consensus
  double min_angle_deg = 1.0;  // widest angle between inlier rays below this: not triangulable
  size_t max_pair_trials = 12;
};

// The point, or nullopt when no consensus of two views has enough parallax, or it lies behind a camera.
std::optional<Eigen::Vector3d> triangulate(const std::vector<Observation>& obs,
                                           const std::vector<CameraPose>& poses, const PinholeCamera& camera,
                                           const TriangulationOptions& options = {});

}  // namespace litgs::host::refine
