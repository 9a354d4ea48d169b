// The thermal-to-LiDAR extrinsic from views of a holed board: each view pairs the hole centres found in
// the image with those found in the scan. Initial value: one rigid fit (Kabsch / Umeyama without scale) of
// the LiDAR centres to the camera's (the board's PnP pose times its layout); then Ceres refines T_cam_lidar
// on the reprojection of the LiDAR centres onto the image centres (Huber loss), views whose error is an
// outlier are left out, and it is solved again.
#pragma once

#include <Eigen/Geometry>
#include <string>
#include <vector>

#include "calib/board_in_image.h"
#include "calib/board_in_scan.h"

namespace litgs::calib {

struct ExtrinsicView {
  std::string name;
  BoardInImage image;
  BoardInScan scan;
};

struct ExtrinsicOptions {
  size_t min_views = 3;
  // A view is left out when its RMS error exceeds median + outlier_k 1.4826 MAD of all views' (and 1 px).
  double outlier_k = 3;
  void check() const;
};

struct ExtrinsicViewReport {
  std::string name;
  bool used = false;
  double rms_px = -1;  // the LiDAR centres reprojected against the image's; -1: not solved with
  double rms_m = -1;   // the LiDAR centres against the camera's (PnP) in 3D
  std::string note;    // why not used
};

struct ExtrinsicResult {
  Eigen::Isometry3d T_cam_lidar = Eigen::Isometry3d::Identity();  // maps LiDAR points into the camera frame
  double rms_px = 0, rms_m = 0;                                   // over the views used
  double rotation_sd_deg = 0, translation_sd_m = 0;  // from the solve's covariance (root of the trace)
  size_t views_used = 0;
  std::vector<ExtrinsicViewReport> views;  // every view, in input order
};

// std::invalid_argument when fewer than min_views views show the board to both sensors, naming how many
// did and why the others did not.
ExtrinsicResult solve_extrinsic(const std::vector<ExtrinsicView>& views, const io::CameraIntrinsics& K,
                                const HoledBoard& board, const ExtrinsicOptions& options);

}  // namespace litgs::calib
