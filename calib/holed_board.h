// The extrinsic's target: a flat board with circular holes at known positions (the approach of FAST-Calib
// and velo2cam), described in board.yaml. Board frame: origin at the board's centre, x to the right and y
// down as seen from the sensors, z into the board (away from them); metres.
#pragma once

#include <Eigen/Core>
#include <filesystem>
#include <string>
#include <vector>

namespace litgs::calib {

struct HoledBoard {
  double width_m = 1.0, height_m = 0.8;  // the board's outline
  double hole_radius_m = 0.12;
  std::vector<Eigen::Vector2d> holes = {{-0.25, -0.2}, {0.25, -0.2}, {0.25, 0.2}, {-0.25, 0.2}};  // centres
  void check() const;                                 // std::invalid_argument naming the field
  std::vector<Eigen::Vector3d> hole_centres() const;  // in the board frame, z = 0
};

// board.yaml:
//   width: 1.0          # metres
//   height: 0.8
//   hole_radius: 0.12
//   holes:              # centres in the board frame: x right, y down, origin at the board's centre
//     - [-0.25, -0.2]
//     - ...
// std::invalid_argument naming the file and the problem (missing key, unknown key, fewer than 4 holes,
// holes overlapping each other or the board's edge).
HoledBoard read_holed_board(const std::filesystem::path& path);
void write_holed_board(const std::filesystem::path& path, const HoledBoard& board);  // atomically

// The holes in the board's cyclic order: by angle about their mean, as seen from the sensors (x right,
// y down). Both sensors list their detections in this order, so the correspondence is a cyclic shift.
std::vector<size_t> cyclic_hole_order(const std::vector<Eigen::Vector2d>& points);

}  // namespace litgs::calib
