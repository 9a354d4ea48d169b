// Surveyed control points as a CSV table: "ID,X,Y,Z,accuracy" with one header line (the Thermitage
// "DUNR-GeomControl.csv" layout: Point ID, Easting (X)(m), Northing (Y)(m), Height (Z)(m), Accuracy (m)).
#pragma once

#include <Eigen/Core>
#include <filesystem>
#include <string>
#include <vector>

namespace litgs::io {

struct ControlPoint {
  std::string id;
  Eigen::Vector3d p_world = Eigen::Vector3d::Zero();  // metres
  double accuracy_m = 0;
};

// IoError (file, line, problem) on a missing file, a row without exactly 5 fields, an empty or repeated id,
// a non-finite number or a negative accuracy.
std::vector<ControlPoint> read_control_points_csv(const std::filesystem::path& path);

}  // namespace litgs::io
