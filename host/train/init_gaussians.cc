#include "host/train/init_gaussians.h"

#include <Eigen/Eigenvalues>
#include <Eigen/Geometry>
#include <algorithm>
#include <cmath>
#include <random>
#include <stdexcept>

#include "host/train/point_kdtree.h"
#include "io/pcd.h"
#include "io/ply_points.h"

namespace litgs::host {
namespace {

constexpr double kShC0 = 0.28209479177387814;

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
    const int x1 = std::min(x0 + 1, static_cast<int>(c.width) - 1),
              y1 = std::min(y0 + 1, static_cast<int>(c.height) - 1);
    const double fx = u - x0, fy = w - y0;
    auto at = [&](int x, int y) {
      return static_cast<double>(v.image[static_cast<size_t>(y) * c.width + x]);
    };
    value =
        (1 - fy) * ((1 - fx) * at(x0, y0) + fx * at(x1, y0)) + fy * ((1 - fx) * at(x0, y1) + fx * at(x1, y1));
    best_depth = q.z;
  }
  return value;
}

// Axes and lengths of a covariance: Sigma = R diag(s)^2 R^T, R a rotation (det +1).
struct GaussianShape {
  Eigen::Vector3d scales;
  Eigen::Quaterniond rotation;
};

GaussianShape shape_of(const Eigen::Matrix3d& cov, double min_scale_m, size_t index) {
  const Eigen::SelfAdjointEigenSolver<Eigen::Matrix3d> eig(cov);
  if (eig.info() != Eigen::Success || !cov.allFinite() || !(eig.eigenvalues()[0] > 0))
    throw std::invalid_argument("initial point " + std::to_string(index) +
                                ": its covariance is not finite and positive definite");
  Eigen::Matrix3d R = eig.eigenvectors();
  if (R.determinant() < 0) R.col(2) = -R.col(2);
  GaussianShape g;
  for (int a = 0; a < 3; ++a) g.scales[a] = std::max(min_scale_m, std::sqrt(eig.eigenvalues()[a]));
  g.rotation = Eigen::Quaterniond(R).normalized();
  return g;
}

// The six covariance fields of a cloud, if it has all of them (none: empty; some: an error).
std::vector<Eigen::Matrix3d> read_covariances(const io::PointCloud& cloud,
                                              const std::filesystem::path& file) {
  static const char* names[6] = {"cov_xx", "cov_xy", "cov_xz", "cov_yy", "cov_yz", "cov_zz"};
  const io::ScalarField* f[6];
  int present = 0;
  for (int k = 0; k < 6; ++k) present += (f[k] = cloud.field(names[k])) != nullptr;
  if (present == 0) return {};
  if (present < 6)
    throw std::invalid_argument(file.string() +
                                ": a per-point covariance needs all six fields cov_xx cov_xy cov_xz "
                                "cov_yy cov_yz cov_zz; the file has " +
                                std::to_string(present));
  std::vector<Eigen::Matrix3d> out(cloud.size());
  for (size_t i = 0; i < cloud.size(); ++i) {
    const double xx = f[0]->values[i], xy = f[1]->values[i], xz = f[2]->values[i], yy = f[3]->values[i],
                 yz = f[4]->values[i], zz = f[5]->values[i];
    out[i] << xx, xy, xz, xy, yy, yz, xz, yz, zz;
    const Eigen::SelfAdjointEigenSolver<Eigen::Matrix3d> eig(out[i]);
    if (!out[i].allFinite() || !(eig.eigenvalues()[0] > 0))
      throw std::invalid_argument(file.string() + ": point " + std::to_string(i) +
                                  ": its covariance is not finite and positive definite");
  }
  return out;
}

}  // namespace

void InitOptions::check() const {
  if (sh_degree > 3) throw std::invalid_argument("InitOptions.sh_degree must be 0..3");
  if (!(initial_opacity > 0 && initial_opacity < 1))
    throw std::invalid_argument("InitOptions.initial_opacity must be in (0, 1)");
  if (neighbours < 1) throw std::invalid_argument("InitOptions.neighbours must be >= 1");
  if (!(min_scale_m > 0)) throw std::invalid_argument("InitOptions.min_scale_m must be > 0");
}

InitPoints load_points(const std::filesystem::path& file, const Eigen::Vector3d& offset) {
  std::string ext = file.extension().string();
  std::transform(ext.begin(), ext.end(), ext.begin(),
                 [](unsigned char c) { return static_cast<char>(std::tolower(c)); });
  io::PointCloud cloud;
  if (ext == ".ply")
    cloud = io::read_ply_points(file);
  else if (ext == ".pcd")
    cloud = io::read_pcd(file);
  else
    throw std::invalid_argument(file.string() + ": initial points must be a .ply or .pcd file");
  if (cloud.size() == 0) throw std::invalid_argument(file.string() + ": the point cloud is empty");
  InitPoints out;
  out.positions.reserve(cloud.size());
  for (const auto& p : cloud.positions) out.positions.push_back(p - offset);
  out.covariances = read_covariances(cloud, file);
  return out;
}

std::vector<double> neighbour_scales(const std::vector<Eigen::Vector3d>& points, const InitOptions& o,
                                     double isolated_scale_m) {
  o.check();
  std::vector<double> scales(points.size(), std::max(o.min_scale_m, isolated_scale_m));
  if (points.size() < 2) return scales;
  PointCloudAdaptor adaptor{points};
  PointKdTree tree(3, adaptor, nanoflann::KDTreeSingleIndexAdaptorParams(10));
  tree.buildIndex();
  const size_t k = std::min<size_t>(o.neighbours + 1, points.size());
  std::vector<uint32_t> idx(k);
  std::vector<double> dist2(k);
  for (size_t i = 0; i < points.size(); ++i) {
    const size_t found = tree.knnSearch(points[i].data(), static_cast<uint32_t>(k), idx.data(), dist2.data());
    double sum = 0;
    size_t used = 0;
    for (size_t j = 0; j < found; ++j)
      if (idx[j] != static_cast<uint32_t>(i)) {
        sum += dist2[j];
        ++used;
      }
    if (used > 0) scales[i] = std::max(o.min_scale_m, std::sqrt(sum / static_cast<double>(used)));
  }
  return scales;
}

std::vector<Eigen::Matrix3d> surfel_covariances(const std::vector<double>& scales,
                                                const std::vector<Eigen::Vector3f>& normals,
                                                const std::vector<uint8_t>& planar, double flatness) {
  if (normals.size() != scales.size() || planar.size() != scales.size())
    throw std::invalid_argument("surfel_covariances: " + std::to_string(scales.size()) + " scales, " +
                                std::to_string(normals.size()) + " normals and " +
                                std::to_string(planar.size()) + " planar flags (need one each per point)");
  if (!(flatness > 0 && flatness <= 1))
    throw std::invalid_argument("surfel_covariances: flatness must be in (0, 1]");
  std::vector<Eigen::Matrix3d> out(scales.size());
  for (size_t i = 0; i < scales.size(); ++i) {
    const double s2 = scales[i] * scales[i];
    out[i] = s2 * Eigen::Matrix3d::Identity();
    if (!planar[i]) continue;
    const Eigen::Vector3d n = normals[i].cast<double>().normalized();
    out[i] -= (1.0 - flatness * flatness) * s2 * n * n.transpose();
  }
  return out;
}

kernels::GaussianModel init_from_points(const std::vector<Eigen::Vector3d>& points, const TrainingData& data,
                                        const InitOptions& o,
                                        const std::vector<Eigen::Matrix3d>& covariances) {
  o.check();
  if (points.empty()) throw std::invalid_argument("init_from_points: no points");
  if (!covariances.empty() && covariances.size() != points.size())
    throw std::invalid_argument("init_from_points: " + std::to_string(covariances.size()) +
                                " covariances for " + std::to_string(points.size()) + " points");
  kernels::GaussianModel m;
  m.channels = 1;
  m.sh_degree = o.sh_degree;
  m.resize(points.size());
  const uint32_t K = m.sh_coeffs();
  const std::vector<double> scales =
      covariances.empty() ? neighbour_scales(points, o, data.scene_extent_m * 0.01) : std::vector<double>{};
  const float logit = std::log(o.initial_opacity / (1.0f - o.initial_opacity));
  for (size_t i = 0; i < points.size(); ++i) {
    Eigen::Vector3d axes_scale = Eigen::Vector3d::Constant(covariances.empty() ? scales[i] : 0.0);
    Eigen::Quaterniond q = Eigen::Quaterniond::Identity();
    if (!covariances.empty()) {
      const GaussianShape shape = shape_of(covariances[i], o.min_scale_m, i);
      axes_scale = shape.scales;
      q = shape.rotation;
    }
    for (int a = 0; a < 3; ++a) {
      m.means[3 * i + a] = static_cast<float>(points[i][a]);
      m.log_scales[3 * i + a] = static_cast<float>(std::log(axes_scale[a]));
    }
    m.quats[4 * i] = static_cast<float>(q.w());
    m.quats[4 * i + 1] = static_cast<float>(q.x());
    m.quats[4 * i + 2] = static_cast<float>(q.y());
    m.quats[4 * i + 3] = static_cast<float>(q.z());
    m.opacity_logits[i] = logit;
    const double value = sample_views(points[i], data);
    m.sh[i * K] = static_cast<float>(((value >= 0 ? value : 0.5) - 0.5) / kShC0);
  }
  return m;
}

kernels::GaussianModel init_random(const TrainingData& data, uint32_t count, uint32_t seed,
                                   const InitOptions& o) {
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
