#include "host/refine/triangulate_track.h"

namespace litgs::host::refine {

std::optional<Eigen::Vector3d> triangulate(const std::vector<Observation>& obs,
                                           const std::vector<CameraPose>& poses, const PinholeCamera& c,
                                           const frontend::TriangulationOptions& options) {
  std::vector<frontend::TriangulationView> views;
  for (const auto& ob : obs) {
    if (!ob.active || ob.frame >= poses.size()) continue;
    const CameraPose& pose = poses[ob.frame];
    frontend::TriangulationView v;
    v.R_cam_world = pose.q_world_cam.conjugate().toRotationMatrix();
    v.t_cam_world = -(v.R_cam_world * pose.p_world_cam);
    v.xy = Eigen::Vector2d((ob.uv.x() - c.cx) / c.fx, (ob.uv.y() - c.cy) / c.fy);
    views.push_back(v);
  }
  const frontend::TriangulatedPoint p = frontend::triangulate(views, c.fx, c.fy, options);
  if (p.outcome != frontend::TriangulationOutcome::kOk) return std::nullopt;
  return p.xyz;
}

}  // namespace litgs::host::refine
