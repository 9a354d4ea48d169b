// Tracks through repetitive texture: a connected component of verified matches that holds two keypoints of
// one image (bricks, windows and panels repeat along the epipolar line) is split into consistent tracks by
// the prior poses instead of being dropped whole.
#pragma once

#include <Eigen/Core>
#include <array>
#include <cstddef>
#include <functional>
#include <optional>
#include <vector>

#include "host/frontend/triangulation.h"
#include "io/sfm_files.h"

namespace litgs::host::frontend {

struct ConflictOptions {
  // An observation agrees with a hypothesis point when its reprojection error through the prior pose is
  // below this (pixels). Wider than triangulation's 2 px: the priors drift between distant frames.
  double max_error_px = 3.0;
  // Two split tracks of one point (the priors drift along a long track) are merged when they share no
  // image, verified matches join them, and their union reprojects within this many times max_error_px;
  // a dropped observation joins a track it is matched to within the same bound (0: neither).
  double merge_factor = 2.0;
  size_t max_hypotheses = 200;  // matches tried as two-view hypotheses per split (evenly sampled)
  void check() const;           // std::invalid_argument naming the field
};

// The geometry of an observation: its image's prior pose and its normalized undistorted coordinates;
// nullopt where the image has no prior pose. Every observation of one image has the same pose: the split
// projects a point once per image (observations_by_image.h).
using ObservationView = std::function<std::optional<TriangulationView>(const io::SfmObservation&)>;

struct ConflictSplit {
  std::vector<io::SfmTrack> tracks;  // each with at most one observation per image, length >= 2
  size_t dropped = 0;                // observations that joined no track
};

// Splits `component` (observations sorted by image; several may share an image) using `edges`, its
// verified matches as pairs of indices into component.observations: repeatedly takes the match whose two-
// view point the most images agree with, re-triangulates it from them, keeps per image the agreeing
// observation with the most matches to the others (the nearest on a tie), and removes them. Then, within
// merge_factor times the bound (the priors' drift), merges tracks of one point that share no image and
// gives dropped observations to the track they are matched to. Deterministic.
ConflictSplit split_conflicting_component(const io::SfmTrack& component,
                                          const std::vector<std::array<size_t, 2>>& edges,
                                          const ObservationView& view, double fx, double fy,
                                          const ConflictOptions& options);

}  // namespace litgs::host::frontend
