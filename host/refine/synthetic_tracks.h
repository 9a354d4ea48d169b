// Feature tracks for development and tests, standing in for the thermal front end: true surface points of
// a synthetic world seen from the true poses (ray-cast visibility), with Gaussian pixel noise and a
// fraction of wrong matches, triangulated with the estimated (drifting) poses, as a front end would.
#pragma once

#include <set>
#include <vector>

#include "host/refine/ba_types.h"
#include "host/refine/triangulate_track.h"
#include "host/synth/geometry.h"

namespace litgs::host::refine {

struct SyntheticTrackOptions {
  int tracks_per_frame = 40;  // new tracks started in each frame
  int max_track_length = 12;  // frames; each track's length is drawn from [2, max]
  // Anchors' tracks: 0 follows each anchor through every frame that sees it (a front end that merges every
  // re-observation into one track); N > 0 tracks it like the other features, for a length drawn from
  // [2, N] from where it comes into view, then as a new track where it is seen again.
  int anchor_track_length = 0;
  double pixel_noise_px = 0.5;  // standard deviation per axis
  double outlier_fraction = 0;  // of observations replaced by a uniformly random pixel (wrong matches)
  double max_range_m = 40;
  uint64_t seed = 7;
  std::set<size_t> frozen_frames;  // frames that repeat the previous image: observations copied from it
  frontend::TriangulationOptions triangulation = frontend::TriangulationOptions::refinement();
};

// anchors_true: the true positions of anchors, each tracked as anchor_track_length says (so that the
// anchor association has something to find). Tracks that cannot be triangulated stay with a NaN position
// and active = false.
std::vector<TrackPoint> synthetic_tracks(const synth::World& world, const std::vector<CameraPose>& truth,
                                         const std::vector<CameraPose>& estimate, const PinholeCamera& camera,
                                         const std::vector<Eigen::Vector3d>& anchors_true,
                                         const SyntheticTrackOptions& options);

}  // namespace litgs::host::refine
