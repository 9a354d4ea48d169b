#include "host/train/init_gaussians.h"

#include <nanoflann.hpp>

#include <algorithm>
#include <cmath>
#include <random>
#include <stdexcept>

#include "io/pcd.h"
#include "io/ply_points.h"

namespace litgs::host {
namespace {

constexpr double kShC0 = 0.28209479177387814;

struct CloudAdaptor {
  const std::vector<Eigen::Vector3d>& pts;
  size_t kdtree_get_point_count() const { return pts.size(); }
  double kdtree_get_pt(size_t i, size_t dim) const { return pts[i][static_cast<int>(dim)]; }
  template <class B>
  bool kdtree_get_bbox(B&) const {
    return false;
  }
};
using KdTree = nanoflann::KDTreeSingleIndexAdaptor<nanoflann::L2_Simple_Adaptor<double, CloudAdaptor>, CloudAdaptor, 3>;

// Intensity of the nearest training view that sees p, or -1.
double sample_views(const Eigen::Vector3d& p, const TrainingData& data) {
  double best_depth = 1e300, value = -1;
  for (const auto& v : data.views) {
    if (v.heldout) continue;
    const auto& c = v.camera;
    const glm::dvec3 q = c.R_cam_world * glm::dvec3(p.x(), p.y(), p.z()) + c.t_cam_world;
    if (q.z <= c.near_m || q.z >= best_depth) continue;
    // Pixel centres at +0.5: continuous coordinate minus 0.5 indexes the pixel grid.
    const double u = c.fx * q.x / q.z + c.cx - 0.5, w = c.fy * q.y / q.z + c.cy - 0.5;
    if (u < 0 || w < 0 || u > c.width - 1.0 || w > c.height - 1.0) continue;
    const int x0 = std::min(static_cast<int>(u), static_cast<int>(c.width) - 1);
    const int y0 = std::min(static_cast<int>(w), static_cast<int>(c.height) - 1);
    const int x1 = std::min(x0 + 1, static_cast<int>(c.width) - 1), y1 = std::min(y0 + 1, static_cast<int>(c.height) - 1);
    const double fx = u - x0, fy = w - y0;
    auto at = [&](int x, int y) { return static_cast<double>(v.image[static_cast<size_t>(y) * c.width + x]); };
    value = (1 - fy) * ((1 - fx) * at(x0, y0) + fx * at(x1, y0)) + fy * ((1 - fx) * at(x0, y1) + fx * at(x1, y1));
    best_depth = q.z;
  }
  return value;
}

}  // namespace

void InitOptions::check() const {
  if (sh_degree > 3) throw std::invalid_argument("InitOptions.sh_degree must be 0..3");
  if (!(initial_opacity > 0 && initial_opacity < 1))
    throw std::invalid_argument("InitOptions.initial_opacity must be in (0, 1)");
  if (neighbours < 1) throw std::invalid_argument("InitOptions.neighbours must be >= 1");
  if (!(min_scale_m > 0)) throw std::invalid_argument("InitOptions.min_scale_m must be > 0");
}

std::vector<Eigen::Vector3d> load_points(const std::filesystem::path& file, const Eigen::Vector3d& offset) {
  std::string ext = file.extension().string();
  std::transform(ext.begin(), ext.end(), ext.begin(), [](unsigned char c) { return static_cast<char>(std::tolower(c)); });
  io::PointCloud cloud;
  if (ext == ".ply")
    cloud = io::read_ply_points(file);
  else if (ext == ".pcd")
    cloud = io::read_pcd(file);
  else
    throw std::invalid_argument(file.string() + ": initial points must be a .ply or .pcd file");
  if (cloud.size() == 0) throw std::invalid_argument(file.string() + ": the point cloud is empty");
  std::vector<Eigen::Vector3d> pts;
  pts.reserve(cloud.size());
  for (const auto& p : cloud.positions) pts.push_back(p - offset);
  return pts;
}

kernels::GaussianModel init_from_points(const std::vector<Eigen::Vector3d>& points, const TrainingData& data,
                                        const InitOptions& o) {
  o.check();
  if (points.empty()) throw std::invalid_argument("init_from_points: no points");
  kernels::GaussianModel m;
  m.channels = 1;
  m.sh_degree = o.sh_degree;
  m.resize(points.size());
  const uint32_t K = m.sh_coeffs();
  CloudAdaptor adaptor{points};
  KdTree tree(3, adaptor, nanoflann::KDTreeSingleIndexAdaptorParams(10));
  tree.buildIndex();
  const size_t k = std::min<size_t>(o.neighbours + 1, points.size());
  std::vector<uint32_t> idx(k);
  std::vector<double> dist2(k);
  const float logit = std::log(o.initial_opacity / (1.0f - o.initial_opacity));
  for (size_t i = 0; i < points.size(); ++i) {
    const size_t found = tree.knnSearch(points[i].data(), static_cast<uint32_t>(k), idx.data(), dist2.data());
    double sum = 0;
    size_t used = 0;
    for (size_t j = 0; j < found; ++j)
      if (idx[j] != static_cast<uint32_t>(i)) {
        sum += dist2[j];
        ++used;
      }
    const double scale = std::max(o.min_scale_m, used ? std::sqrt(sum / static_cast<double>(used)) : data.scene_extent_m * 0.01);
    for (int a = 0; a < 3; ++a) {
      m.means[3 * i + a] = static_cast<float>(points[i][a]);
      m.log_scales[3 * i + a] = static_cast<float>(std::log(scale));
    }
    m.quats[4 * i] = 1.0f;
    m.opacity_logits[i] = logit;
    const double value = sample_views(points[i], data);
    m.sh[i * K] = static_cast<float>(((value >= 0 ? value : 0.5) - 0.5) / kShC0);
  }
  return m;
}

kernels::GaussianModel init_random(const TrainingData& data, uint32_t count, uint32_t seed, const InitOptions& o) {
  if (count == 0) throw std::invalid_argument("init_random: count must be positive");
  Eigen::Vector3d mean = Eigen::Vector3d::Zero();
  for (const auto& v : data.views) {
    const glm::dvec3 c = -glm::transpose(v.camera.R_cam_world) * v.camera.t_cam_world;
    mean += Eigen::Vector3d(c.x, c.y, c.z);
  }
  mean /= static_cast<double>(std::max<size_t>(1, data.views.size()));
  std::mt19937 rng(seed);
  std::uniform_real_distribution<double> u(-1.0, 1.0);
  std::vector<Eigen::Vector3d> pts(count);
  for (auto& p : pts) p = mean + data.scene_extent_m * Eigen::Vector3d(u(rng), u(rng), u(rng));
  return init_from_points(pts, data, o);
}

}  // namespace litgs::host
