// The holed board in one LiDAR scan of a spinning LiDAR (rings of returns): the board's segment of the scan,
// its plane, the boundary points of each hole along the rings, a circle of the board's hole radius fitted to
// each hole's boundary, and the hole centres in the LiDAR frame.
#pragma once

#include <Eigen/Core>
#include <string>
#include <vector>

#include "calib/holed_board.h"

namespace litgs::calib {

struct BoardInScanOptions {
  // The beam's full divergence: at an edge the footprint touching the board returns a board point up to half
  // the footprint past the edge. Velodyne VLP-16/32C: about 3 mrad.
  double beam_divergence_rad = 0.003;
  double min_range_m = 0.5, max_range_m = 15;  // the board is searched for within these ranges
  void check() const;                          // std::invalid_argument naming the field
};

struct BoardInScan {
  bool found = false;
  std::string why_not;                   // where not found
  std::vector<Eigen::Vector3d> centres;  // the holes' centres, LiDAR frame, in the board's hole order
  Eigen::Vector3d normal = Eigen::Vector3d::Zero();  // the board's normal, pointing away from the sensor
  size_t board_points = 0;                           // returns in the board's segment
  double plane_rms_m = 0;                            // their RMS distance to the fitted plane
  std::vector<int> boundary_points;                  // per hole: boundary points the circle was fitted to
  double layout_rms_m = 0;                           // the fitted centres against the board's rigid layout
};

// The LiDAR frame is x forward, y left, z up; the board must stand roughly upright (its y axis within 45
// degrees of the LiDAR's down) so that its holes can be told apart on a symmetric board.
BoardInScan find_board_in_scan(const std::vector<Eigen::Vector3d>& points_lidar, const HoledBoard& board,
                               const BoardInScanOptions& options);

}  // namespace litgs::calib
