// A guard against a refinement that makes the poses worse when no ground truth can show it: a share of the
// tracks is held back from the solve; afterwards each held-back track is triangulated through the prior
// poses and, separately, through the refined poses, and its reprojection error measured in each. Poses
// that fit the solved tracks better but explain the unseen ones worse than the priors are not kept.
#pragma once

#include <cstddef>
#include <string>
#include <vector>

#include "host/refine/ba_types.h"

namespace litgs::host::refine {

struct HoldoutOptions {
  size_t every = 8;  // every Nth track (by index) is held back; 0: no guard
  // The refined poses are kept when the held-back tracks' median reprojection error through them is at
  // most (1 + tolerance) times theirs through the priors.
  double tolerance = 0.02;
  size_t min_tracks = 10;  // fewer held-back tracks with a point both ways: no verdict, the refinement stands
  // An observation takes part when it lies within this of its track's consensus point through either pose
  // set (pixels): wrong matches in a held-back track would otherwise drag both fits.
  double agree_px = 4;
  void check() const;  // std::invalid_argument naming the field
};

// Moves every Nth track of `points` into the returned set (they take no part in the solve).
std::vector<TrackPoint> hold_out_tracks(std::vector<TrackPoint>& points, const HoldoutOptions& options);

struct HoldoutVerdict {
  size_t tracks = 0;        // held back
  size_t tracks_used = 0;   // triangulated through both pose sets
  size_t observations = 0;  // of the tracks used
  double prior_median_px = 0, refined_median_px = 0;
  bool measured = false;     // tracks_used >= min_tracks
  bool keep_refined = true;  // false: the refined poses explain the held-back tracks worse
  std::string summary;       // one line for the report
};

HoldoutVerdict judge_on_held_out(const std::vector<TrackPoint>& held_out,
                                 const std::vector<CameraPose>& priors,
                                 const std::vector<CameraPose>& refined, const PinholeCamera& camera,
                                 const HoldoutOptions& options);

}  // namespace litgs::host::refine
