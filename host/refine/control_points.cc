#include "host/refine/control_points.h"

#include <stdexcept>

#include "host/refine/bundle_adjustment.h"
#include "host/refine/weights.h"
#include "io/robust_stats.h"

namespace litgs::host::refine {

ControlPointErrors control_point_errors(const io::MetashapeDocument& doc,
                                        const std::vector<io::ControlPoint>& points,
                                        const Eigen::Vector3d& world_offset_m, const PinholeCamera& camera,
                                        const std::vector<CameraPose>& priors,
                                        const std::vector<CameraPose>& refined) {
  ControlPointErrors r;
  std::vector<double> before, after;
  for (const auto& marker : doc.markers) {
    const io::ControlPoint* cp = nullptr;
    for (const auto& p : points)
      if (p.id == marker.label) cp = &p;
    if (!cp) continue;
    const Eigen::Vector3d X = cp->p_world - world_offset_m;
    for (const auto& ob : marker.observations) {
      const io::MetashapeCamera* cam = doc.camera(ob.camera_id);
      if (!cam || !cam->T_chunk_cam) {
        ++r.unmatched_cameras;
        continue;
      }
      const Eigen::Vector3d c = doc.T_world_cam(*cam).topRightCorner<3, 1>() - world_offset_m;
      size_t frame = priors.size();
      for (size_t f = 0; f < priors.size(); ++f)
        if ((priors[f].p_world_cam - c).norm() < 1e-3) frame = f;
      if (frame == priors.size()) {
        ++r.unmatched_cameras;
        continue;
      }
      const Eigen::Vector2d uv = ob.uv - Eigen::Vector2d(0.5, 0.5);
      before.push_back(reprojection_error_px(priors[frame], camera, X, uv));
      after.push_back(reprojection_error_px(refined[frame], camera, X, uv));
    }
  }
  if (before.empty())
    throw std::invalid_argument(
        "control points: no marker observation matches a surveyed point and a frame of the scene");
  r.observations = before.size();
  r.median_prior_px = io::median(before);
  r.median_refined_px = io::median(after);
  return r;
}

}  // namespace litgs::host::refine
