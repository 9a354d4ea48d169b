// Surveyed control points as a check of refined poses (issue 14, DUNR): each marker's image observations
// (a Metashape camera XML, io/metashape.h) against the projection of its surveyed coordinates (a CSV,
// io/control_points.h) through a set of camera poses; the median error in pixels.
#pragma once

#include <Eigen/Core>
#include <vector>

#include "host/refine/ba_types.h"
#include "io/control_points.h"
#include "io/metashape.h"

namespace litgs::host::refine {

struct ControlPointErrors {
  size_t observations = 0;       // marker observations in a camera that matches a frame
  size_t unmatched_cameras = 0;  // observations whose camera matches no frame's prior pose
  double median_prior_px = 0, median_refined_px = 0;
};

// Frames are found by their prior pose: the XML camera whose position (minus the scene's recentring
// `world_offset_m`) lies within 1 mm of a frame's prior position is that frame. Observations are in
// Metashape's pixel convention (corner origin): 0.5 px is taken off to meet the scene's (pixel centres).
// Markers without a surveyed point in `points` (matched by label) are skipped. std::invalid_argument when
// no observation matches.
ControlPointErrors control_point_errors(const io::MetashapeDocument& doc,
                                        const std::vector<io::ControlPoint>& points,
                                        const Eigen::Vector3d& world_offset_m, const PinholeCamera& camera,
                                        const std::vector<CameraPose>& priors,
                                        const std::vector<CameraPose>& refined);

}  // namespace litgs::host::refine
