// A point cloud as read from PCD or PLY: positions plus the optional per-point attributes the engine uses.
#pragma once

#include <Eigen/Core>
#include <string>
#include <vector>

namespace litgs::io {

// Any other per-point scalar of the file (e.g. PLY "error_px"), kept by name, as double.
struct ScalarField {
  std::string name;
  std::vector<double> values;  // [N]
};

struct PointCloud {
  // Positions are double: world maps sit near 1000 m in some data sets (recentre before float32 GPU work).
  std::vector<Eigen::Vector3d> positions;  // [N], metres, in the frame the file states (world or sensor)
  std::vector<float> intensity;            // [N] or empty
  std::vector<Eigen::Vector3f> normals;    // [N] or empty (unit length not enforced)
  std::vector<ScalarField> extra;          // each [N]

  size_t size() const { return positions.size(); }
  // Throws std::invalid_argument if an attribute is neither empty nor of size N.
  void check() const;
  // The extra field called `name`, or nullptr.
  const ScalarField* field(const std::string& name) const;
};

}  // namespace litgs::io
