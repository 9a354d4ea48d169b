// The bundle adjustment's residuals (host/refine/cost_functions.h): each value against an independent
// computation, and each automatic Jacobian against Ceres' central differences of the same functor.
#include <ceres/ceres.h>
#include <gtest/gtest.h>

#include <random>

#include "host/refine/bundle_adjustment.h"
#include "host/refine/cost_functions.h"

namespace litgs::host::refine {
namespace {

Eigen::Quaterniond rotation(double rx, double ry, double rz) {
  return Eigen::Quaterniond(Eigen::AngleAxisd(rz, Eigen::Vector3d::UnitZ()) *
                            Eigen::AngleAxisd(ry, Eigen::Vector3d::UnitY()) *
                            Eigen::AngleAxisd(rx, Eigen::Vector3d::UnitX()));
}

// Evaluates `cost` with its Jacobians at `blocks`, and the central-difference Jacobians of the same functor,
// and expects them to agree to `tolerance` (absolute, on entries scaled to order 1 by the caller's choice).
void expect_jacobians_agree(ceres::CostFunction& automatic, ceres::CostFunction& numeric,
                            std::vector<double*> blocks, double tolerance) {
  const int m = automatic.num_residuals();
  const std::vector<int32_t>& sizes = automatic.parameter_block_sizes();
  std::vector<std::vector<double>> ja(sizes.size()), jn(sizes.size());
  std::vector<double*> pa, pn;
  for (size_t b = 0; b < sizes.size(); ++b) {
    ja[b].assign(static_cast<size_t>(m * sizes[b]), 0);
    jn[b].assign(static_cast<size_t>(m * sizes[b]), 0);
    pa.push_back(ja[b].data());
    pn.push_back(jn[b].data());
  }
  std::vector<double> ra(static_cast<size_t>(m)), rn(static_cast<size_t>(m));
  ASSERT_TRUE(automatic.Evaluate(blocks.data(), ra.data(), pa.data()));
  ASSERT_TRUE(numeric.Evaluate(blocks.data(), rn.data(), pn.data()));
  for (int i = 0; i < m; ++i) EXPECT_NEAR(ra[static_cast<size_t>(i)], rn[static_cast<size_t>(i)], 1e-12);
  for (size_t b = 0; b < sizes.size(); ++b)
    for (size_t k = 0; k < ja[b].size(); ++k)
      EXPECT_NEAR(ja[b][k], jn[b][k], tolerance) << "block " << b << " entry " << k;
}

TEST(RefineCostFunctions, ReprojectionIsThePinholeProjectionLessTheObservation) {
  PinholeCamera c{400, 410, 160, 128, 320, 256};
  CameraPose pose{0, rotation(0.1, -0.2, 0.3), {0.5, -0.3, 1.0}};
  const Eigen::Vector3d X(2.0, 1.0, 9.0);
  const Eigen::Vector2d uv(150.0, 140.0);
  const Reprojection f{uv, c};
  double r[2];
  ASSERT_TRUE(f(pose.q_world_cam.coeffs().data(), pose.p_world_cam.data(), X.data(), r));
  // Independently: the point in the camera frame through the rotation matrix.
  const Eigen::Vector3d x = pose.q_world_cam.toRotationMatrix().transpose() * (X - pose.p_world_cam);
  EXPECT_NEAR(r[0], c.fx * x.x() / x.z() + c.cx - uv.x(), 1e-9);
  EXPECT_NEAR(r[1], c.fy * x.y() / x.z() + c.cy - uv.y(), 1e-9);
  EXPECT_NEAR(std::hypot(r[0], r[1]), reprojection_error_px(pose, c, X, uv), 1e-9);

  ceres::AutoDiffCostFunction<Reprojection, 2, 4, 3, 3> automatic(new Reprojection(f));
  ceres::NumericDiffCostFunction<Reprojection, ceres::CENTRAL, 2, 4, 3, 3> numeric(new Reprojection(f));
  Eigen::Vector3d Xv = X;
  expect_jacobians_agree(automatic, numeric,
                         {pose.q_world_cam.coeffs().data(), pose.p_world_cam.data(), Xv.data()}, 1e-5);
}

TEST(RefineCostFunctions, APointBehindTheCameraGivesALargeFiniteResidual) {
  const Reprojection f{{0, 0}, PinholeCamera{400, 400, 0, 0, 320, 256}};
  const Eigen::Quaterniond q = Eigen::Quaterniond::Identity();
  const Eigen::Vector3d p = Eigen::Vector3d::Zero(), X(1, 0, -2);
  double r[2];
  ASSERT_TRUE(f(q.coeffs().data(), p.data(), X.data(), r));
  EXPECT_TRUE(std::isfinite(r[0]) && std::isfinite(r[1]));
  EXPECT_GT(std::abs(r[0]), 1e5);
}

TEST(RefineCostFunctions, PointToPlaneIsTheSignedDistanceOverSigma) {
  PlaneRef plane;
  plane.n = Eigen::Vector3d(1, 2, 2).normalized();
  plane.l = Eigen::Vector3d(0.5, 0, 1);
  const PointToPlane f{plane, 1 / 0.02};
  const Eigen::Vector3d on = plane.l + Eigen::Vector3d(2, -1, 0);  // (2, -1, 0) is orthogonal to n
  const Eigen::Vector3d off = on + 0.03 * plane.n;
  double r;
  ASSERT_TRUE(f(on.data(), &r));
  EXPECT_NEAR(r, 0, 1e-12);
  ASSERT_TRUE(f(off.data(), &r));
  EXPECT_NEAR(r, 1.5, 1e-12);  // 3 cm at sigma 2 cm, on the normal's side
  ceres::AutoDiffCostFunction<PointToPlane, 1, 3> automatic(new PointToPlane(f));
  ceres::NumericDiffCostFunction<PointToPlane, ceres::CENTRAL, 1, 3> numeric(new PointToPlane(f));
  Eigen::Vector3d X = off;
  expect_jacobians_agree(automatic, numeric, {X.data()}, 1e-6);
}

TEST(RefineCostFunctions, ScanPointToPlaneIsThePlacedPointsSignedDistanceOverSigma) {
  PlaneRef plane;
  plane.n = Eigen::Vector3d(0, 0.6, 0.8);
  plane.l = Eigen::Vector3d(1, 2, 3);
  CameraPose pose{0, rotation(0.2, -0.1, 0.4), {0.3, 1.0, -0.5}};
  const Eigen::Vector3d x_cam(0.7, -1.2, 4.0);
  const ScanPointToPlane f{x_cam, plane, 1 / 0.02};
  double r;
  ASSERT_TRUE(f(pose.q_world_cam.coeffs().data(), pose.p_world_cam.data(), &r));
  // Independently: through the rotation matrix.
  const Eigen::Vector3d w = pose.q_world_cam.toRotationMatrix() * x_cam + pose.p_world_cam;
  EXPECT_NEAR(r, plane.n.dot(w - plane.l) / 0.02, 1e-9);
  // Moving the camera 3 cm along the normal moves the residual by 1.5 sigma.
  CameraPose moved = pose;
  moved.p_world_cam += 0.03 * plane.n;
  double r_moved;
  ASSERT_TRUE(f(moved.q_world_cam.coeffs().data(), moved.p_world_cam.data(), &r_moved));
  EXPECT_NEAR(r_moved - r, 1.5, 1e-9);
  ceres::AutoDiffCostFunction<ScanPointToPlane, 1, 4, 3> automatic(new ScanPointToPlane(f));
  ceres::NumericDiffCostFunction<ScanPointToPlane, ceres::CENTRAL, 1, 4, 3> numeric(new ScanPointToPlane(f));
  expect_jacobians_agree(automatic, numeric, {pose.q_world_cam.coeffs().data(), pose.p_world_cam.data()},
                         1e-5);
}

TEST(RefineCostFunctions, RelativePoseIsZeroAtTheMeasuredMotionAndGrowsWithTheError) {
  const Eigen::Quaterniond qi = rotation(0.05, 0.1, -0.2), qj = rotation(0.06, 0.08, -0.15);
  const Eigen::Vector3d pi(1, 2, 0.5), pj(1.3, 2.1, 0.45);
  const Eigen::Quaterniond dq = qi.conjugate() * qj;
  const Eigen::Vector3d dp = qi.conjugate() * (pj - pi);
  const RelativePose f{dq, dp, 1 / 0.01, 1 / 0.001};
  double r[6];
  ASSERT_TRUE(f(qi.coeffs().data(), pi.data(), qj.coeffs().data(), pj.data(), r));
  for (double v : r) EXPECT_NEAR(v, 0, 1e-9);
  // j moved 2 cm along i's x axis and turned by 3 mrad about j's own z: residuals 2 sigma and 3 sigma.
  const Eigen::Vector3d pj2 = pj + qi * Eigen::Vector3d(0.02, 0, 0);
  const Eigen::Quaterniond qj2 = qj * Eigen::Quaterniond(Eigen::AngleAxisd(0.003, Eigen::Vector3d::UnitZ()));
  ASSERT_TRUE(f(qi.coeffs().data(), pi.data(), qj2.coeffs().data(), pj2.data(), r));
  EXPECT_NEAR(r[0], 2, 1e-9);
  EXPECT_NEAR(r[1], 0, 1e-9);
  EXPECT_NEAR(r[2], 0, 1e-9);
  EXPECT_NEAR(r[5], 3, 1e-5);  // 2 sin(theta / 2) / sigma
  // The sign of a quaternion does not matter: -q is the same rotation.
  const Eigen::Quaterniond flipped(-qj2.w(), -qj2.x(), -qj2.y(), -qj2.z());
  double rf[6];
  ASSERT_TRUE(f(qi.coeffs().data(), pi.data(), flipped.coeffs().data(), pj2.data(), rf));
  for (int k = 0; k < 6; ++k) EXPECT_NEAR(rf[k], r[k], 1e-9);

  ceres::AutoDiffCostFunction<RelativePose, 6, 4, 3, 4, 3> automatic(new RelativePose(f));
  ceres::NumericDiffCostFunction<RelativePose, ceres::CENTRAL, 6, 4, 3, 4, 3> numeric(new RelativePose(f));
  Eigen::Quaterniond a = qi, b = qj2;
  Eigen::Vector3d pa = pi, pb = pj2;
  // Entries reach 2 / sigma_r = 2000: the difference's error scales with them.
  expect_jacobians_agree(automatic, numeric, {a.coeffs().data(), pa.data(), b.coeffs().data(), pb.data()},
                         1e-3);
}

TEST(RefineCostFunctions, AbsolutePoseWithAZeroInverseSigmaIgnoresThatHalf) {
  const Eigen::Quaterniond q0 = rotation(0.2, 0.1, 0.3);
  const Eigen::Vector3d p0(4, 5, 6);
  const AbsolutePose orientation_only{q0, p0, 0.0, 1 / 0.002};
  const Eigen::Vector3d p = p0 + Eigen::Vector3d(1, 1, 1);  // far off in position
  const Eigen::Quaterniond q = q0 * Eigen::Quaterniond(Eigen::AngleAxisd(0.004, Eigen::Vector3d::UnitX()));
  double r[6];
  ASSERT_TRUE(orientation_only(q.coeffs().data(), p.data(), r));
  for (int k = 0; k < 3; ++k) EXPECT_EQ(r[k], 0);
  EXPECT_NEAR(r[3], 2, 1e-5);  // 4 mrad at 2 mrad
  const AbsolutePose both{q0, p0, 1 / 0.5, 1 / 0.002};
  ASSERT_TRUE(both(q.coeffs().data(), p.data(), r));
  for (int k = 0; k < 3; ++k) EXPECT_NEAR(r[k], 2, 1e-12);  // 1 m at 0.5 m
  ceres::AutoDiffCostFunction<AbsolutePose, 6, 4, 3> automatic(new AbsolutePose(both));
  ceres::NumericDiffCostFunction<AbsolutePose, ceres::CENTRAL, 6, 4, 3> numeric(new AbsolutePose(both));
  Eigen::Quaterniond qv = q;
  Eigen::Vector3d pv = p;
  expect_jacobians_agree(automatic, numeric, {qv.coeffs().data(), pv.data()}, 1e-3);
}

TEST(RefineCostFunctions, AnchorPriorIsTheWhitenedOffset) {
  Eigen::Matrix3d cov;
  cov << 4e-4, 1e-4, 0, 1e-4, 9e-4, 0, 0, 0, 1e-2;
  const Eigen::Matrix3d L = cov.llt().matrixL();
  const Eigen::Matrix3d sqrt_info = L.inverse();
  const Eigen::Vector3d a(1, 2, 3), X(1.01, 1.97, 3.2);
  const AnchorPrior f{a, sqrt_info};
  double r[3];
  ASSERT_TRUE(f(X.data(), r));
  // |r|^2 is the Mahalanobis distance of the offset under the anchor's covariance.
  const Eigen::Vector3d e = X - a;
  EXPECT_NEAR(r[0] * r[0] + r[1] * r[1] + r[2] * r[2], e.dot(cov.inverse() * e), 1e-9);
  ceres::AutoDiffCostFunction<AnchorPrior, 3, 3> automatic(new AnchorPrior(f));
  ceres::NumericDiffCostFunction<AnchorPrior, ceres::CENTRAL, 3, 3> numeric(new AnchorPrior(f));
  Eigen::Vector3d Xv = X;
  expect_jacobians_agree(automatic, numeric, {Xv.data()}, 1e-5);
}

}  // namespace
}  // namespace litgs::host::refine
