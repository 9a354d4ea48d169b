// `litgs-engine refine SCENE`: the refinement on a scene directory (docs/refinement.md). Reads the scene,
// the prior poses (poses_prior.txt when a previous run kept it, else poses.txt), the LiDAR map's plane fits
// and the anchors; gets tracks from a source; writes the refined poses.txt (keeping the input as
// poses_prior.txt), refine/points.pcd (refined points with their anchor and plane status) and refine.json.
#pragma once

#include <filesystem>
#include <optional>
#include <string>

#include "host/refine/control_points.h"
#include "host/refine/refine.h"
#include "host/refine/scan_check.h"
#include "host/refine/sfm_tracks.h"
#include "host/refine/synthetic_tracks.h"

namespace litgs::host::refine {

struct SceneRefineOptions {
  RefineOptions refine;
  // Where the tracks come from. "auto" and "sfm": the front end's SCENE/sfm/ (`litgs-engine match`,
  // sfm_tracks.h; an error naming the fix when it is missing). "oracle": projected from a synthetic
  // scene's true poses and world (synthetic_tracks.h): for experiments that separate the refinement from
  // the front end, never a result of the method.
  std::string tracks = "auto";
  SyntheticTrackOptions synthetic;
  // The priors' kind: "auto" reads scene.yaml's poses_origin (absolute for Metashape and COLMAP imports:
  // a pose prior on every frame; odometry: relative priors between neighbours); "absolute" | "odometry"
  // override it. refine.absolute_priors is set from it.
  std::string priors = "auto";
  // The upstream estimator's anchors: "auto" uses them with oracle tracks only. On the front end's own
  // tracks an anchor (a map point at a high gradient) is associated with whichever keypoint lies within a
  // pixel or two of it, rarely the same physical point, and the anchor priors made the synthetic facade's
  // poses worse (docs/refinement.md, "Anchors with the front end's tracks"). "on" | "off" override it;
  // refine.use_anchors is set from it.
  std::string anchors = "auto";
  // After a solve, the LiDAR scans of every Nth frame against the map's planes (scan_check.h): refined
  // poses that put them farther from the map than the priors do are not kept.
  ScanCheckOptions scan_check;
  // With both: the surveyed control points' reprojection through the prior and the refined poses.
  std::filesystem::path control_points_csv, markers_xml;
};

struct SceneRefineReport {
  RefineReport refine;
  bool has_truth = false;
  double ate_before_m = 0, ate_after_m = 0;  // SE(3)-aligned, against gt/poses.txt at the frame times
  double ate_rejected_m = -1;  // of the solve a guard turned down (-1: none); the truth's view of the verdict
  double plane_rms_true_m = -1;  // refined points on true planes (gt/map.pcd plane ids): RMS distance
  size_t points_written = 0;
  std::string tracks;            // the source used: "sfm" or "oracle"
  std::string priors;            // the priors used: "absolute" or "odometry", and why
  bool anchors = false;          // used
  bool absolute_priors = false;  // a pose prior on every frame (see priors)
  SfmTrackReport sfm;            // with tracks == "sfm"
  std::optional<ControlPointErrors> control;
  ScanVerdict scans;
};

SceneRefineReport refine_scene(const std::filesystem::path& scene_dir, const SceneRefineOptions& options);

}  // namespace litgs::host::refine
