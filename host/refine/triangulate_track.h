// A refinement track's point through a set of poses: its active observations handed to the engine's one
// triangulation (host/frontend/triangulation.h) with the refinement's options.
#pragma once

#include <optional>
#include <vector>

#include "host/frontend/triangulation.h"
#include "host/refine/ba_types.h"

namespace litgs::host::refine {

// The point, or nullopt when no consensus of two views has enough parallax, or it lies behind a camera.
std::optional<Eigen::Vector3d> triangulate(
    const std::vector<Observation>& obs, const std::vector<CameraPose>& poses, const PinholeCamera& camera,
    const frontend::TriangulationOptions& options = frontend::TriangulationOptions::refinement());

}  // namespace litgs::host::refine
