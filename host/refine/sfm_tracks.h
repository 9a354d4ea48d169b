// The front end's tracks (SCENE/sfm/, io/sfm_files.h) as the bundle adjustment's points: a triangulated
// track gives the views that agree with its point and the point as the start; a track the front end could
// not triangulate gives all its views and is triangulated here with the prior poses (triangulate_track.h), or
// stays inactive. Keypoints are undistorted with the scene camera first (the adjustment is pinhole).
#pragma once

#include <vector>

#include "host/refine/ba_types.h"
#include "host/refine/triangulate_track.h"
#include "io/scene_types.h"
#include "io/sfm_files.h"

namespace litgs::host::refine {

struct SfmTrackReport {
  size_t tracks = 0, from_front_end_points = 0, triangulated_here = 0, untriangulated = 0;
};

// std::invalid_argument naming the problem when an observation names an image beyond `priors` or a
// keypoint its image lacks.
std::vector<TrackPoint> sfm_tracks(
    const io::SfmData& sfm, const io::CameraIntrinsics& camera, const std::vector<CameraPose>& priors,
    SfmTrackReport* report = nullptr,
    const frontend::TriangulationOptions& triangulation = frontend::TriangulationOptions::refinement());

}  // namespace litgs::host::refine
