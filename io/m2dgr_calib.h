// The M2DGR benchmark's calibration file (calibration_results.txt): free text in an "opencv-matrix" style,
// one block per sensor ("%% Cam-thermal"), each with "% Extrinsic [to LIDAR]", "% Intrinsic",
// "% Distortion Coefficients" and "% Image Size" comments, each followed by "data: [ ... ]" (possibly over
// several lines). The real file has quirks this reader copes with, and says so in `notes`:
// - the thermal intrinsic matrix is printed transposed ([fx 0 0; 0 fy 0; cx cy 1]);
// - a full-width comma (U+FF0C) separates two numbers; rows end without commas;
// Anything else malformed (a stray ']', a wrong number count, a matrix that is neither K nor K^T, a
// non-rigid extrinsic) is an IoError naming the line.
#pragma once

#include <Eigen/Core>
#include <filesystem>
#include <string>
#include <vector>

namespace litgs::io {

struct M2dgrCamera {
  std::string block;  // the block name after "%%", trimmed (e.g. "Cam-thermal")
  // "Extrinsic [to LIDAR]": maps camera points into the LiDAR frame (for the thermal camera, camera z goes to
  // LiDAR x). Identity if the block has none (has_extrinsic false).
  Eigen::Matrix4d T_lidar_cam = Eigen::Matrix4d::Identity();
  bool has_extrinsic = false;
  double fx = 0, fy = 0, cx = 0, cy = 0;  // pixels, pixel-centre convention of OpenCV
  bool has_intrinsics = false;
  std::vector<double> distortion;  // OpenCV radtan order: k1 k2 p1 p2
  int width = 0, height = 0;       // 0 if the block has no "Image Size"
  std::vector<std::string> notes;  // quirks met and how they were read, each with its line
};

// Reads one camera block (name compared after trimming, e.g. "Cam-thermal"). IoError if the file or the
// block is missing, or on any malformed data in that block (blocks not asked for are not parsed).
M2dgrCamera read_m2dgr_camera(const std::filesystem::path& path, const std::string& block = "Cam-thermal");

}  // namespace litgs::io
