#include "host/synth/estimator_model.h"

#include <Eigen/Cholesky>
#include <cmath>
#include <optional>
#include <stdexcept>

#include "host/synth/thermal_camera.h"
#include "io/lens_distortion.h"

namespace litgs::host::synth {
namespace {

Eigen::Vector3d random_unit(Rng& rng) {
  Eigen::Vector3d v(rng.normal(), rng.normal(), rng.normal());
  while (v.norm() < 1e-6) v = Eigen::Vector3d(rng.normal(), rng.normal(), rng.normal());
  return v.normalized();
}

Eigen::Quaterniond exp_so3(const Eigen::Vector3d& w) {
  const double a = w.norm();
  if (a < 1e-15) return Eigen::Quaterniond::Identity();
  return Eigen::Quaterniond(Eigen::AngleAxisd(a, w / a));
}

}  // namespace

std::string EstimatorNoiseOptions::check() const {
  if (!(drift_m_per_m >= 0)) return "drift_m_per_m: must be >= 0";
  if (!(drift_rad_per_m >= 0)) return "drift_rad_per_m: must be >= 0";
  if (!(pose_noise_m >= 0)) return "pose_noise_m: must be >= 0";
  if (!(pose_noise_rad >= 0)) return "pose_noise_rad: must be >= 0";
  if (anchors_per_frame < 0 || anchors_per_frame > 100000) return "anchors_per_frame: must be in [0, 1e5]";
  if (!(anchor_pixel_sigma_px > 0))
    return "anchor_pixel_sigma_px: must be > 0 (covariances are positive definite)";
  if (!(anchor_depth_sigma_m > 0)) return "anchor_depth_sigma_m: must be > 0";
  if (!(anchor_min_gradient_raw >= 0)) return "anchor_min_gradient_raw: must be >= 0";
  if (anchor_border_px < 1) return "anchor_border_px: must be >= 1";
  return "";
}

std::vector<io::TumPose> drift_poses(const std::vector<io::TumPose>& truth,
                                     const std::vector<double>& distance_m, const EstimatorNoiseOptions& o,
                                     Rng& rng) {
  if (truth.size() != distance_m.size()) throw std::invalid_argument("drift_poses: one distance per pose");
  const Eigen::Vector3d drift_dir = random_unit(rng), drift_axis = random_unit(rng);
  std::vector<io::TumPose> out;
  out.reserve(truth.size());
  for (size_t i = 0; i < truth.size(); ++i) {
    const double s = distance_m[i] - distance_m.front();
    // World-side drift: the estimate is T_drift * T_true, T_drift a rotation about the first pose's position
    // plus a translation, both growing with the distance travelled.
    const Eigen::Quaterniond q_drift = exp_so3(drift_axis * o.drift_rad_per_m * s);
    const Eigen::Vector3d pivot = truth.front().p_world;
    io::TumPose p = truth[i];
    p.p_world = pivot + q_drift * (truth[i].p_world - pivot) + drift_dir * o.drift_m_per_m * s;
    p.p_world += o.pose_noise_m * Eigen::Vector3d(rng.normal(), rng.normal(), rng.normal());
    const Eigen::Vector3d jitter =
        o.pose_noise_rad * Eigen::Vector3d(rng.normal(), rng.normal(), rng.normal());
    p.q_world_body = (q_drift * truth[i].q_world_body * exp_so3(jitter)).normalized();
    out.push_back(p);
  }
  return out;
}

std::vector<io::Anchor> pick_anchors(const World& world, const io::CameraIntrinsics& K,
                                     const Eigen::Isometry3d& T_world_cam, const EstimatorNoiseOptions& o,
                                     Rng& rng, std::vector<Eigen::Vector3d>& truth) {
  std::vector<io::Anchor> out;
  const int b = o.anchor_border_px;
  if (K.width <= 2 * b + 2 || K.height <= 2 * b + 2) return out;
  // Bounded attempts: a textureless view yields few anchors, as it would for the real estimator.
  for (int attempt = 0;
       attempt < 20 * o.anchors_per_frame && static_cast<int>(out.size()) < o.anchors_per_frame; ++attempt) {
    const double x = rng.uniform(b, K.width - 1 - b), y = rng.uniform(b, K.height - 1 - b);
    const double gx =
        pixel_radiance(world, K, T_world_cam, x + 1, y) - pixel_radiance(world, K, T_world_cam, x - 1, y);
    const double gy =
        pixel_radiance(world, K, T_world_cam, x, y + 1) - pixel_radiance(world, K, T_world_cam, x, y - 1);
    if (std::hypot(gx, gy) / 2 < o.anchor_min_gradient_raw) continue;
    const std::optional<Eigen::Vector3d> ray = io::pixel_ray(K, x, y);
    if (!ray) continue;
    const Eigen::Vector3d d_cam = ray->normalized();
    const Eigen::Vector3d dir = T_world_cam.linear() * d_cam;
    const auto hit = world.cast({T_world_cam.translation(), dir}, 0.05, 1e4);
    if (!hit) continue;
    // Covariance: lateral from a pixel error at this depth, longer along the ray (depth is the weak axis).
    const double lateral = hit->range_m * o.anchor_pixel_sigma_px / K.fx;
    Eigen::Matrix3d basis;
    basis.col(2) = dir;
    basis.col(0) = dir.unitOrthogonal();
    basis.col(1) = dir.cross(basis.col(0));
    const Eigen::Vector3d sigma(lateral, lateral, o.anchor_depth_sigma_m);
    io::Anchor a;
    a.cov_m2 = basis * sigma.cwiseAbs2().asDiagonal() * basis.transpose();
    a.cov_m2 = 0.5 * (a.cov_m2 + a.cov_m2.transpose()).eval();
    // The error is drawn from the reported covariance: e = L z, L L^T = cov.
    const Eigen::Matrix3d L = a.cov_m2.llt().matrixL();
    a.p_world = hit->point + L * Eigen::Vector3d(rng.normal(), rng.normal(), rng.normal());
    out.push_back(a);
    truth.push_back(hit->point);
  }
  return out;
}

}  // namespace litgs::host::synth
