// The ground truth planes of a (synthetic) scene as a PlanarMap: gt/map.pcd's points, each with the normal of
// the gt/planes.txt plane its plane_id names. Points on no plane (poles, curved surfaces) take part as
// occluders only (planar 0). Each point stands for a disc of the map's spacing, so that the truth, too, is
// the surface a pixel sees rather than a point behind it.
#pragma once

#include <memory>

#include "host/train/lidar_planes.h"
#include "io/scene.h"

namespace litgs::host {

// nullptr when the scene has no gt/map.pcd with a plane_id field, or no gt/planes.txt.
std::unique_ptr<PlanarMap> true_planar_map(const io::Scene& scene);

}  // namespace litgs::host
