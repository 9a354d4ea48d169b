// The LiDAR scans as measurements of the poses they were taken from (docs/refinement.md, "Scans in the
// solve"). A map built through drifting poses drifts with them, and holding the image points to its planes
// holds the poses to the drift. Each scan is instead tied rigidly to its camera frame, and its points are
// held to the local planes of the map that the current poses build from all the scans: where the poses
// place two scans of one wall apart, the wall is thick, and the solve closes the gap by moving the poses.
// Rebuilt every round, as the poses move. No Ceres here; the residual is cost_functions.h's
// ScanPointToPlane.
#pragma once

#include <Eigen/Core>
#include <Eigen/Geometry>
#include <string>
#include <vector>

#include "host/refine/ba_types.h"
#include "host/train/lidar_planes.h"

namespace litgs::host::refine {

struct ScanAlignmentOptions {
  size_t map_points_per_scan = 4000;      // evenly subsampled, for the map the poses build
  size_t residual_points_per_scan = 300;  // of those, the ones held to its planes (planar ones only)
  // The map's averaging voxel: coarse first, halved each round down to voxel_m (`litgs-engine map`'s
  // default). Through drifting priors a wall seen from several scans is smeared into a slab that a fine
  // voxel's plane fits call non-planar, and its points would drop out of the first solve.
  double voxel_start_m = 0.4, voxel_m = 0.1;
  double search_radius_m = 0.3;  // nearest planar map point within this, or two of the round's voxels
  // Point-to-plane gate per round: start, halved each round, never below the floor (as the image points').
  double gate_start_m = 0.2, gate_floor_m = 0.03;
  // In the rounds the scans are in, the track points' plane term on this map too, instead of the scene's
  // LiDAR map (which the drifting prior poses placed): one map that moves with the poses. It lowered the
  // refined ATE most where the LiDAR map drifts (docs/experiments.md, 2026-12-07).
  bool points_on_scan_map = true;
  // The refinement's round (0-based) the scans join in. Their map is built through the current poses, and
  // through poses that still carry most of the priors' drift it is smeared: the links it gives hold the
  // solve in that state (docs/refinement.md). From the fifth round the image term has done most of its work.
  size_t from_round = 4;
  double voxel_at(size_t round) const;
  void check() const;  // std::invalid_argument naming the field
};

// One scan in the solve: its points (LiDAR frame, deskewed to its stamp), the frame it is tied to, and its
// pose in that frame's camera (T_cam_lidar through the priors: the extrinsic and the motion between the
// frame's stamp and the scan's).
struct RefineScan {
  uint32_t frame = 0;
  Eigen::Isometry3d T_cam_scan = Eigen::Isometry3d::Identity();
  std::vector<Eigen::Vector3d> points_lidar;
};

// A scan point held to a plane of the map: its position in its frame's camera.
struct ScanPlaneLink {
  uint32_t frame = 0;
  Eigen::Vector3d x_cam = Eigen::Vector3d::Zero();
  PlaneRef plane;
};

struct ScanAssociationReport {
  size_t scans = 0, map_points = 0, planar_map_points = 0, links = 0;
  double gate_m = 0;
};

// The map the scans build through `poses`: voxel centroids and their local plane fits.
PlanarMap scan_map(const std::vector<RefineScan>& scans, const std::vector<CameraPose>& poses, size_t round,
                   const ScanAlignmentOptions& options);

// The scans' points' links to the planes of `map` (round r's gate).
std::vector<ScanPlaneLink> associate_scan_planes(const std::vector<RefineScan>& scans,
                                                 const std::vector<CameraPose>& poses, const PlanarMap& map,
                                                 size_t round, const ScanAlignmentOptions& options,
                                                 ScanAssociationReport& report);
// The same on the map the scans build through `poses`.
std::vector<ScanPlaneLink> associate_scan_planes(const std::vector<RefineScan>& scans,
                                                 const std::vector<CameraPose>& poses, size_t round,
                                                 const ScanAlignmentOptions& options,
                                                 ScanAssociationReport& report);

// RMS of the links' point-to-plane distances through `poses` (metres; 0 without links).
double scan_plane_rms_m(const std::vector<ScanPlaneLink>& links, const std::vector<CameraPose>& poses);

}  // namespace litgs::host::refine
