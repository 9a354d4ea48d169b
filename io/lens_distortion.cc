#include "io/lens_distortion.h"

#include <Eigen/LU>
#include <cmath>

namespace litgs::io {
namespace {

double coefficient(const CameraIntrinsics& k, size_t i) {
  return i < k.distortion.size() ? k.distortion[i] : 0.0;
}

// theta_d(theta) of the equidistant model.
double fisheye_theta_d(const CameraIntrinsics& k, double th) {
  const double t2 = th * th;
  return th * (1 + t2 * (coefficient(k, 0) +
                         t2 * (coefficient(k, 1) + t2 * (coefficient(k, 2) + t2 * coefficient(k, 3)))));
}

double fisheye_theta_d_derivative(const CameraIntrinsics& k, double th) {
  const double t2 = th * th;
  return 1 + t2 * (3 * coefficient(k, 0) +
                   t2 * (5 * coefficient(k, 1) + t2 * (7 * coefficient(k, 2) + t2 * 9 * coefficient(k, 3))));
}

constexpr int kMaxNewtonSteps = 50;
constexpr double kTolerance = 1e-12;

}  // namespace

Eigen::Vector2d distort_normalized(const CameraIntrinsics& k, const Eigen::Vector2d& p) {
  const double x = p.x(), y = p.y();
  if (k.model == CameraModel::kEquidistant) {
    const double r = std::hypot(x, y);
    if (r < 1e-12) return p;
    return p * (fisheye_theta_d(k, std::atan(r)) / r);
  }
  const double r2 = x * x + y * y;
  const double radial = 1 + r2 * (coefficient(k, 0) + r2 * (coefficient(k, 1) + r2 * coefficient(k, 4)));
  const double p1 = coefficient(k, 2), p2 = coefficient(k, 3);
  return {x * radial + 2 * p1 * x * y + p2 * (r2 + 2 * x * x),
          y * radial + p1 * (r2 + 2 * y * y) + 2 * p2 * x * y};
}

std::optional<Eigen::Vector2d> undistort_normalized(const CameraIntrinsics& k, const Eigen::Vector2d& d) {
  if (k.distortion.empty()) return d;
  if (k.model == CameraModel::kEquidistant) {
    const double r_d = d.norm();
    if (r_d < 1e-12) return d;
    double th = r_d;  // theta_d = theta without distortion
    for (int i = 0; i < kMaxNewtonSteps; ++i) {
      const double slope = fisheye_theta_d_derivative(k, th);
      if (!(slope > 0)) return std::nullopt;  // past the model's monotonic range
      const double step = (fisheye_theta_d(k, th) - r_d) / slope;
      th -= step;
      if (!(th >= 0 && th < M_PI / 2)) return std::nullopt;
      if (std::abs(step) < kTolerance) return d * (std::tan(th) / r_d);
    }
    return std::nullopt;
  }
  const double k1 = coefficient(k, 0), k2 = coefficient(k, 1), p1 = coefficient(k, 2), p2 = coefficient(k, 3),
               k3 = coefficient(k, 4);
  Eigen::Vector2d p = d;
  for (int i = 0; i < kMaxNewtonSteps; ++i) {
    const double x = p.x(), y = p.y(), r2 = x * x + y * y;
    const double radial = 1 + r2 * (k1 + r2 * (k2 + r2 * k3));
    const double radial_slope = k1 + r2 * (2 * k2 + 3 * k3 * r2);  // d radial / d r2
    Eigen::Matrix2d J;
    J << radial + 2 * x * x * radial_slope + 2 * p1 * y + 6 * p2 * x,
        2 * x * y * radial_slope + 2 * p1 * x + 2 * p2 * y,  //
        2 * x * y * radial_slope + 2 * p1 * x + 2 * p2 * y,
        radial + 2 * y * y * radial_slope + 6 * p1 * y + 2 * p2 * x;
    if (!(std::abs(J.determinant()) > 1e-9)) return std::nullopt;  // the model folds over here
    const Eigen::Vector2d step = J.inverse() * (distort_normalized(k, p) - d);
    p -= step;
    if (!p.allFinite()) return std::nullopt;
    if (step.norm() < kTolerance) {
      // Only the preimage on the model's monotonic branch is the ray: past the fold, a point on the far
      // side (radial < 0) or beyond the turning point also distorts to d.
      const double q2 = p.squaredNorm();
      const double q_radial = 1 + q2 * (k1 + q2 * (k2 + q2 * k3));
      const double q_slope = k1 + q2 * (2 * k2 + 3 * k3 * q2);
      if (q_radial > 0 && q_radial + 2 * q2 * q_slope > 0) return p;
      return std::nullopt;
    }
  }
  return std::nullopt;
}

std::optional<Eigen::Vector3d> pixel_ray(const CameraIntrinsics& k, double u, double v) {
  const auto p = undistort_normalized(k, {(u - k.cx) / k.fx, (v - k.cy) / k.fy});
  if (!p) return std::nullopt;
  return Eigen::Vector3d(p->x(), p->y(), 1);
}

}  // namespace litgs::io
