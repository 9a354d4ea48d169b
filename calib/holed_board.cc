#include "calib/holed_board.h"

#include <yaml-cpp/yaml.h>

#include <algorithm>
#include <cmath>
#include <numeric>
#include <sstream>
#include <stdexcept>

#include "io/atomic_file.h"

namespace litgs::calib {

void HoledBoard::check() const {
  if (!(width_m > 0 && height_m > 0 && std::isfinite(width_m) && std::isfinite(height_m)))
    throw std::invalid_argument("board: width and height must be > 0 (metres)");
  if (!(hole_radius_m > 0 && std::isfinite(hole_radius_m)))
    throw std::invalid_argument("board: hole_radius must be > 0 (metres)");
  if (holes.size() < 4)  // the pose of a plane from three points is ambiguous
    throw std::invalid_argument("board: at least 4 holes are needed, got " + std::to_string(holes.size()));
  for (size_t k = 0; k < holes.size(); ++k) {
    const Eigen::Vector2d& h = holes[k];
    if (!h.allFinite())
      throw std::invalid_argument("board: hole " + std::to_string(k + 1) + " is not finite");
    if (std::abs(h.x()) + hole_radius_m >= width_m / 2 || std::abs(h.y()) + hole_radius_m >= height_m / 2)
      throw std::invalid_argument("board: hole " + std::to_string(k + 1) + " reaches the board's edge");
    for (size_t m = 0; m < k; ++m)
      if ((holes[m] - h).norm() < 2.5 * hole_radius_m)
        throw std::invalid_argument("board: holes " + std::to_string(m + 1) + " and " +
                                    std::to_string(k + 1) + " are less than 2.5 radii apart");
  }
}

std::vector<Eigen::Vector3d> HoledBoard::hole_centres() const {
  std::vector<Eigen::Vector3d> out;
  for (const Eigen::Vector2d& h : holes) out.emplace_back(h.x(), h.y(), 0.0);
  return out;
}

HoledBoard read_holed_board(const std::filesystem::path& path) {
  const std::string where = path.string() + ": ";
  YAML::Node root;
  try {
    root = YAML::LoadFile(path.string());
  } catch (const YAML::BadFile&) {
    throw std::invalid_argument(where + "cannot be read");
  } catch (const YAML::Exception& e) {
    throw std::invalid_argument(where + "not YAML (" + std::string(e.what()) + ")");
  }
  if (!root.IsMap())
    throw std::invalid_argument(where + "a map of width, height, hole_radius and holes is needed");
  for (const auto& kv : root) {
    const std::string key = kv.first.as<std::string>();
    if (key != "width" && key != "height" && key != "hole_radius" && key != "holes")
      throw std::invalid_argument(where + "unknown key '" + key + "' (width, height, hole_radius, holes)");
  }
  HoledBoard b;
  try {
    const auto number = [&](const char* key) {
      if (!root[key]) throw std::invalid_argument(where + "missing key '" + key + "'");
      return root[key].as<double>();
    };
    b.width_m = number("width");
    b.height_m = number("height");
    b.hole_radius_m = number("hole_radius");
    if (!root["holes"] || !root["holes"].IsSequence())
      throw std::invalid_argument(where + "'holes' must be a list of [x, y] centres");
    b.holes.clear();
    for (const auto& h : root["holes"]) {
      if (!h.IsSequence() || h.size() != 2)
        throw std::invalid_argument(where + "each hole is [x, y] in metres");
      b.holes.emplace_back(h[0].as<double>(), h[1].as<double>());
    }
  } catch (const YAML::Exception& e) {
    throw std::invalid_argument(where + "a value is not a number (" + std::string(e.what()) + ")");
  }
  try {
    b.check();
  } catch (const std::invalid_argument& e) {
    throw std::invalid_argument(where + e.what());
  }
  return b;
}

void write_holed_board(const std::filesystem::path& path, const HoledBoard& b) {
  b.check();
  io::write_file_atomic(path, [&](std::ostream& s) {
    s.precision(17);
    s << "# A flat board with circular holes (litgs-engine calib extrinsic). Metres; board frame: origin at\n"
         "# the board's centre, x right and y down as seen from the sensors.\n"
      << "width: " << b.width_m << "\nheight: " << b.height_m << "\nhole_radius: " << b.hole_radius_m
      << "\nholes:\n";
    for (const Eigen::Vector2d& h : b.holes) s << "  - [" << h.x() << ", " << h.y() << "]\n";
  });
}

std::vector<size_t> cyclic_hole_order(const std::vector<Eigen::Vector2d>& points) {
  Eigen::Vector2d mean = Eigen::Vector2d::Zero();
  for (const auto& p : points) mean += p;
  mean /= static_cast<double>(std::max<size_t>(points.size(), 1));
  std::vector<size_t> order(points.size());
  std::iota(order.begin(), order.end(), size_t{0});
  const auto angle = [&](size_t k) { return std::atan2(points[k].y() - mean.y(), points[k].x() - mean.x()); };
  std::sort(order.begin(), order.end(), [&](size_t a, size_t b) { return angle(a) < angle(b); });
  return order;
}

}  // namespace litgs::calib
