// Associations that feed the bundle adjustment (docs/refinement.md, "Associations"):
// - anchors to tracks: each anchor projected into every frame where it lies in view and is not hidden
//   behind the LiDAR map; every track with an observation within the radius there votes for it; a track
//   takes the anchor it agrees with in most frames (at least min_agreeing frames and half of those where
//   both are seen; ties to the nearer) if its point lies within the anchor's covariance (a chi^2 gate),
//   and each anchor goes to one track at most;
// - points to LiDAR planes: short tracks through the depth image of the map in their middle frame, long
//   tracks through the nearest planar map point; both within a radius that shrinks over the rounds.
#pragma once

#include <memory>
#include <vector>

#include "host/refine/ba_types.h"
#include "host/train/lidar_planes.h"

namespace litgs::host::refine {

struct AnchorAssociationOptions {
  // Search radius: radius_px * shrink^round, at least min_radius_px. A wider first radius (16 px) reaches
  // anchors under larger drift but associated wrong tracks on the synthetic street and facade (worse ATE
  // and plane RMS; docs/refinement.md, "Associations"): the default stays small.
  double radius_px = 3;
  double shrink = 0.5;
  double min_radius_px = 3;
  size_t min_agreeing = 2;
  double occlusion_margin_m = 0.3;  // an anchor farther than the map's surface by more than this is hidden
  // A track agrees with an anchor only if its point, triangulated again from its own observations with
  // the current poses, lies within the anchor's covariance: (X - a)^T Sigma^-1 (X - a) <= gate_chi2, the
  // 99% quantile of chi^2 with 3 degrees of freedom. Pixel agreement alone takes neighbouring tracks, even
  // through the true poses (the synthetic street: docs/refinement.md, "Why the anchors hurt").
  double gate_chi2 = 11.34;
  // An anchor that two or more tracks pass the gate for is ambiguous and takes none: on a textured wall an
  // estimator's map point (a patch at a high gradient) and a detector's keypoint need not be the same
  // physical point, and a neighbour within the gate pulls the poses by centimetres (the facade's own
  // tracks: docs/refinement.md).
  bool reject_ambiguous = true;
};

struct AnchorAssociationReport {
  size_t anchors_in_view = 0;  // anchors seen by at least one frame
  size_t anchored_tracks = 0;
  size_t occluded_projections = 0;
  size_t ambiguous_anchors = 0;  // passed by two or more tracks: not used (reject_ambiguous)
};

// Sets TrackPoint::anchor. `map` may be null (no occlusion check).
AnchorAssociationReport associate_anchors(std::vector<TrackPoint>& points,
                                          const std::vector<AnchorPoint>& anchors,
                                          const std::vector<CameraPose>& poses, const PinholeCamera& camera,
                                          const PlanarMap* map, const AnchorAssociationOptions& options,
                                          size_t round = 0);

struct PlaneAssociationOptions {
  size_t long_track = 5;  // tracks with this many active observations or more use the nearest map point
  double radius_m = 0.5;  // first round's search radius and largest accepted point-to-plane distance
  double shrink = 0.5;    // radius factor per round
  double min_radius_m = 0.05;
};

struct PlaneAssociationReport {
  size_t by_depth_image = 0, by_nearest_point = 0, unassociated = 0;
  double radius_m = 0;
};

// Re-associates every active point with a local plane of the map (TrackPoint::has_plane, plane) for
// round `round` (0-based).
class PlaneAssociator {
 public:
  PlaneAssociator(const PlanarMap& map, const PinholeCamera& camera);
  ~PlaneAssociator();
  PlaneAssociationReport associate(std::vector<TrackPoint>& points, const std::vector<CameraPose>& poses,
                                   size_t round, const PlaneAssociationOptions& options) const;

 private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
};

}  // namespace litgs::host::refine
