// The residuals of the pose refinement's bundle adjustment (bundle_adjustment.h), as Ceres functors
// templated for automatic differentiation. Poses are T_world_cam = (q, p): p_world = q * p_cam + p; q is
// Eigen's quaternion with its coefficients stored x, y, z, w (Ceres' EigenQuaternionManifold). The
// reprojection residual is in pixels (its robust loss is scaled in pixels); the others are whitened, divided
// by their standard deviation.
// tests/refine/test_cost_functions.cc checks each against an independent computation and its automatic
// Jacobian against central differences.
#pragma once

#include <Eigen/Core>
#include <Eigen/Geometry>

#include "host/refine/ba_types.h"

namespace litgs::host::refine {

// Pixel residual of a world point seen by a camera with T_world_cam = (q, p).
struct Reprojection {
  Eigen::Vector2d uv;
  PinholeCamera c;
  template <class T>
  bool operator()(const T* q_, const T* p_, const T* X_, T* r) const {
    const Eigen::Map<const Eigen::Quaternion<T>> q(q_);
    const Eigen::Map<const Eigen::Matrix<T, 3, 1>> p(p_), X(X_);
    const Eigen::Matrix<T, 3, 1> x = q.conjugate() * (X - p);
    // A point behind the camera gives a large finite residual, not a division by ~0.
    const T z = x.z() > T(1e-3) ? x.z() : T(1e-3);
    r[0] = T(c.fx) * x.x() / z + T(c.cx) - T(uv.x());
    r[1] = T(c.fy) * x.y() / z + T(c.cy) - T(uv.y());
    return true;
  }
};

// Signed distance of a world point to its LiDAR plane (normal n through l), over sigma.
struct PointToPlane {
  PlaneRef plane;
  double inv_sigma;
  template <class T>
  bool operator()(const T* X_, T* r) const {
    const Eigen::Map<const Eigen::Matrix<T, 3, 1>> X(X_);
    r[0] = T(inv_sigma) * plane.n.cast<T>().dot(X - plane.l.cast<T>());
    return true;
  }
};

// Signed distance of a LiDAR point, fixed in its frame's camera (x_cam), placed through that frame's pose
// T_world_cam = (q, p), to its map plane, over sigma.
struct ScanPointToPlane {
  Eigen::Vector3d x_cam;
  PlaneRef plane;
  double inv_sigma;
  template <class T>
  bool operator()(const T* q_, const T* p_, T* r) const {
    const Eigen::Map<const Eigen::Quaternion<T>> q(q_);
    const Eigen::Map<const Eigen::Matrix<T, 3, 1>> p(p_);
    const Eigen::Matrix<T, 3, 1> x = q * x_cam.cast<T>() + p;
    r[0] = T(inv_sigma) * plane.n.cast<T>().dot(x - plane.l.cast<T>());
    return true;
  }
};

// A small rotation error e as the whitened angle-axis 2 vec(e) / sigma (radians), the same for e and -e.
template <class T>
void rotation_residual(const Eigen::Quaternion<T>& e, double inv_sigma_r, T* r) {
  const T sign = e.w() < T(0) ? T(-1) : T(1);
  for (int k = 0; k < 3; ++k) r[k] = T(2 * inv_sigma_r) * e.vec()[k] * sign;
}

// Relative motion T_i^-1 T_j against the measured one, whitened; rotation as 2 * vec(dq) (radians, small).
struct RelativePose {
  Eigen::Quaterniond dq;
  Eigen::Vector3d dp;
  double inv_sigma_t, inv_sigma_r;
  template <class T>
  bool operator()(const T* qi_, const T* pi_, const T* qj_, const T* pj_, T* r) const {
    const Eigen::Map<const Eigen::Quaternion<T>> qi(qi_), qj(qj_);
    const Eigen::Map<const Eigen::Matrix<T, 3, 1>> pi(pi_), pj(pj_);
    const Eigen::Matrix<T, 3, 1> t = qi.conjugate() * (pj - pi);
    const Eigen::Quaternion<T> e = dq.cast<T>().conjugate() * (qi.conjugate() * qj);
    for (int k = 0; k < 3; ++k) r[k] = T(inv_sigma_t) * (t[k] - T(dp[k]));
    rotation_residual(e, inv_sigma_r, r + 3);
    return true;
  }
};

// A pose against a prior (q0, p0); rotation as 2 * vec(q0^-1 q) (radians, small). A zero inverse sigma
// switches its half off (the orientation-only prior of an odometry).
struct AbsolutePose {
  Eigen::Quaterniond q0;
  Eigen::Vector3d p0;
  double inv_sigma_t, inv_sigma_r;
  template <class T>
  bool operator()(const T* q_, const T* p_, T* r) const {
    const Eigen::Map<const Eigen::Quaternion<T>> q(q_);
    const Eigen::Map<const Eigen::Matrix<T, 3, 1>> p(p_);
    const Eigen::Quaternion<T> e = q0.cast<T>().conjugate() * q;
    for (int k = 0; k < 3; ++k) r[k] = T(inv_sigma_t) * (p[k] - T(p0[k]));
    rotation_residual(e, inv_sigma_r, r + 3);
    return true;
  }
};

// A track point against an anchor a of the upstream estimator, whitened by L^-1 of its covariance.
struct AnchorPrior {
  Eigen::Vector3d a;
  Eigen::Matrix3d sqrt_info;
  template <class T>
  bool operator()(const T* X_, T* r) const {
    const Eigen::Map<const Eigen::Matrix<T, 3, 1>> X(X_);
    const Eigen::Matrix<T, 3, 1> e = sqrt_info.cast<T>() * (X - a.cast<T>());
    for (int k = 0; k < 3; ++k) r[k] = e[k];
    return true;
  }
};

}  // namespace litgs::host::refine
