#include "io/point_cloud.h"

#include <stdexcept>

namespace litgs::io {

void PointCloud::check() const {
  const size_t n = positions.size();
  const auto bad = [n](const std::string& what, size_t m) {
    throw std::invalid_argument("PointCloud: " + what + " has " + std::to_string(m) + " entries for " +
                                std::to_string(n) + " points");
  };
  if (!intensity.empty() && intensity.size() != n) bad("intensity", intensity.size());
  if (!normals.empty() && normals.size() != n) bad("normals", normals.size());
  for (const auto& f : extra)
    if (f.values.size() != n) bad("field '" + f.name + "'", f.values.size());
}

const ScalarField* PointCloud::field(const std::string& name) const {
  for (const auto& f : extra)
    if (f.name == name) return &f;
  return nullptr;
}

}  // namespace litgs::io
