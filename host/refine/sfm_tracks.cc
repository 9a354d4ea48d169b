#include "host/refine/sfm_tracks.h"

#include <limits>
#include <stdexcept>
#include <string>

#include "host/frontend/verification.h"

namespace litgs::host::refine {

std::vector<TrackPoint> sfm_tracks(const io::SfmData& sfm, const io::CameraIntrinsics& camera,
                                   const std::vector<CameraPose>& priors, SfmTrackReport* report,
                                   const frontend::TriangulationOptions& triangulation) {
  SfmTrackReport r;
  std::vector<std::vector<Eigen::Vector2d>> undistorted;
  for (const auto& image : sfm.images)
    undistorted.push_back(frontend::undistort_keypoints(camera, image.keypoints));
  const PinholeCamera pinhole{camera.fx, camera.fy, camera.cx, camera.cy, camera.width, camera.height};
  auto observations = [&](const std::vector<io::SfmObservation>& views) {
    std::vector<Observation> out;
    for (const auto& v : views) {
      if (v.image >= priors.size() || v.image >= undistorted.size())
        throw std::invalid_argument("sfm/: an observation names image " + std::to_string(v.image) +
                                    " but the scene has " + std::to_string(priors.size()) + " frames");
      if (v.keypoint >= undistorted[v.image].size())
        throw std::invalid_argument("sfm/: image " + std::to_string(v.image) + " has no keypoint " +
                                    std::to_string(v.keypoint));
      Observation ob;
      ob.frame = v.image;
      ob.uv = undistorted[v.image][v.keypoint];
      out.push_back(ob);
    }
    return out;
  };
  std::vector<TrackPoint> points;
  for (const auto& track : sfm.tracks) {
    ++r.tracks;
    TrackPoint p;
    const bool has_point = track.point >= 0 && static_cast<size_t>(track.point) < sfm.points.size();
    if (has_point) {
      const io::SfmPoint& sp = sfm.points[static_cast<size_t>(track.point)];
      p.obs = observations(sp.observations);
      p.X = sp.xyz;
      ++r.from_front_end_points;
    } else {
      p.obs = observations(track.observations);
      const auto X = p.obs.size() >= 2 ? triangulate(p.obs, priors, pinhole, triangulation) : std::nullopt;
      p.X = X ? *X : Eigen::Vector3d::Constant(std::numeric_limits<double>::quiet_NaN());
      p.active = X.has_value();
      ++(X ? r.triangulated_here : r.untriangulated);
    }
    points.push_back(std::move(p));
  }
  if (report) *report = r;
  return points;
}

}  // namespace litgs::host::refine
