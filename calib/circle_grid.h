// Detection of OpenCV's asymmetric circle grid in thermal frames: circle (row i, column j) centred at
// ((2j + i mod 2) spacing, i spacing) on the board; `--grid 4x11` is 4 columns and 11 rows. Circles may be
// hotter or colder than the board (two materials or emissivities).
#pragma once

#include <Eigen/Core>
#include <string>
#include <vector>

#include "io/image.h"

namespace litgs::calib {

struct CircleGrid {
  int cols = 4, rows = 11;
  double spacing_m = 0.05;
  std::vector<Eigen::Vector3d> board_points() const;  // OpenCV's order: row by row, metres, z = 0
  void check() const;                                 // std::invalid_argument naming the field
};

// "COLSxROWS" and the spacing; std::invalid_argument naming what is wrong.
CircleGrid parse_circle_grid(const std::string& cols_x_rows, double spacing_m);

enum class Polarity { kAuto, kHot, kCold };
Polarity parse_polarity(const std::string& name);  // auto | hot | cold

struct GridDetection {
  bool found = false;
  std::string polarity;                  // "hot" or "cold" where found
  std::vector<Eigen::Vector2d> centres;  // pixels (centre of the top-left pixel at 0, 0), OpenCV's order
  std::string why_not;                   // where not found
};

// A one-channel frame as 8 bits: a 16-bit frame by the front end's 0.5 / 99.5 percentile stretch, an 8-bit
// one as it is. std::invalid_argument for more channels.
io::Image thermal_8bit(const io::Image& image);

// The image as 8 bits: a 16-bit frame by its 0.5 / 99.5 percentile stretch, an 8-bit one as it is; then
// CLAHE where asked. The grid is searched for with hot circles, cold circles or (auto) both.
GridDetection detect_circle_grid(const io::Image& image, const CircleGrid& grid, Polarity polarity,
                                 bool clahe);

}  // namespace litgs::calib
