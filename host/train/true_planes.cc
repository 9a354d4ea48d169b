#include "host/train/true_planes.h"

namespace litgs::host {

std::unique_ptr<PlanarMap> true_planar_map(const io::Scene& scene) {
  if (!scene.gt || !scene.gt->map || scene.gt->planes.empty()) return nullptr;
  const io::PointCloud& m = *scene.gt->map;
  const io::ScalarField* id = m.field("plane_id");
  if (!id) return nullptr;
  auto planes = std::make_unique<PlanarMap>();
  for (size_t i = 0; i < m.size(); ++i) {
    const double pid = id->values[i];
    const bool on_plane = pid >= 0 && pid < static_cast<double>(scene.gt->planes.size());
    planes->points.push_back(m.positions[i].cast<float>());
    planes->centres.push_back(m.positions[i].cast<float>());  // a true point lies on its plane
    planes->normals.push_back(
        on_plane ? Eigen::Vector3f(scene.gt->planes[static_cast<size_t>(pid)].n.cast<float>())
                 : Eigen::Vector3f(Eigen::Vector3f::Zero()));
    planes->planar.push_back(on_plane ? 1 : 0);
  }
  assign_surfel_radii(*planes);
  return planes;
}

}  // namespace litgs::host
