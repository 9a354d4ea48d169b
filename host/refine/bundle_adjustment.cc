#include "host/refine/bundle_adjustment.h"

#include <ceres/ceres.h>
#include <ceres/rotation.h>

#include <chrono>
#include <cmath>
#include <limits>

#include "host/refine/cost_functions.h"

namespace litgs::host::refine {

double reprojection_error_px(const CameraPose& pose, const PinholeCamera& c, const Eigen::Vector3d& X,
                             const Eigen::Vector2d& uv) {
  const Eigen::Vector3d x = pose.q_world_cam.conjugate() * (X - pose.p_world_cam);
  if (!(x.z() > 1e-3)) return std::numeric_limits<double>::infinity();
  return (Eigen::Vector2d(c.fx * x.x() / x.z() + c.cx, c.fy * x.y() / x.z() + c.cy) - uv).norm();
}

BaSolveSummary solve_bundle_adjustment(BaProblem& b) {
  const auto start = std::chrono::steady_clock::now();
  std::vector<CameraPose>& poses = *b.poses;
  const std::vector<CameraPose>& priors = *b.priors;
  const size_t n = poses.size();
  auto variable = [&](size_t f) { return b.variable.empty() || b.variable[f]; };
  BaSolveSummary s;
  ceres::Problem::Options po;
  po.manifold_ownership = ceres::TAKE_OWNERSHIP;
  ceres::Problem problem(po);
  std::vector<bool> in_problem(n, false);
  auto add_pose = [&](size_t f) {
    if (in_problem[f]) return;
    in_problem[f] = true;
    problem.AddParameterBlock(poses[f].q_world_cam.coeffs().data(), 4, new ceres::EigenQuaternionManifold);
    problem.AddParameterBlock(poses[f].p_world_cam.data(), 3);
    if (!variable(f)) {
      problem.SetParameterBlockConstant(poses[f].q_world_cam.coeffs().data());
      problem.SetParameterBlockConstant(poses[f].p_world_cam.data());
    } else {
      ++s.variable_frames;
    }
  };
  const BaWeights& w = b.weights;
  for (auto& p : *b.points) {
    if (!p.active || p.active_observations() < 2) continue;
    bool sees_variable = false;
    for (const auto& ob : p.obs) sees_variable |= ob.active && variable(ob.frame);
    if (!sees_variable) continue;
    ++s.points;
    double weight_sum = 0;
    size_t count = 0;
    for (const auto& ob : p.obs) {
      if (!ob.active) continue;
      add_pose(ob.frame);
      auto* cost =
          new ceres::AutoDiffCostFunction<Reprojection, 2, 4, 3, 3>(new Reprojection{ob.uv, b.camera});
      problem.AddResidualBlock(
          cost,
          new ceres::ScaledLoss(new ceres::CauchyLoss(w.pixel_loss_px), ob.weight, ceres::TAKE_OWNERSHIP),
          poses[ob.frame].q_world_cam.coeffs().data(), poses[ob.frame].p_world_cam.data(), p.X.data());
      ++s.reprojection_residuals;
      weight_sum += ob.weight;
      ++count;
    }
    if (b.use_planes && p.has_plane) {
      auto* cost =
          new ceres::AutoDiffCostFunction<PointToPlane, 1, 3>(new PointToPlane{p.plane, 1 / w.plane_sigma_m});
      problem.AddResidualBlock(
          cost,
          new ceres::ScaledLoss(new ceres::CauchyLoss(1.0), weight_sum / static_cast<double>(count),
                                ceres::TAKE_OWNERSHIP),
          p.X.data());
      ++s.plane_residuals;
    }
    if (b.use_anchor_priors && b.anchors && p.anchor >= 0) {
      const size_t a = static_cast<size_t>(p.anchor);
      auto* cost = new ceres::AutoDiffCostFunction<AnchorPrior, 3, 3>(
          new AnchorPrior{(*b.anchors)[a].p_world, b.anchor_sqrt_information[a]});
      problem.AddResidualBlock(cost, new ceres::CauchyLoss(w.anchor_loss), p.X.data());
      ++s.anchor_residuals;
    }
  }
  if (b.scan_links)
    for (const ScanPlaneLink& l : *b.scan_links) {
      if (!variable(l.frame)) continue;
      add_pose(l.frame);
      auto* cost = new ceres::AutoDiffCostFunction<ScanPointToPlane, 1, 4, 3>(
          new ScanPointToPlane{l.x_cam, l.plane, 1 / w.scan_sigma_m});
      problem.AddResidualBlock(
          cost, new ceres::ScaledLoss(new ceres::CauchyLoss(1.0), w.scan_weight, ceres::TAKE_OWNERSHIP),
          poses[l.frame].q_world_cam.coeffs().data(), poses[l.frame].p_world_cam.data());
      ++s.scan_residuals;
    }
  // Odometry priors between consecutive frames with at least one variable.
  for (size_t f = 0; f + 1 < n; ++f) {
    if (!variable(f) && !variable(f + 1)) continue;
    add_pose(f);
    add_pose(f + 1);
    const Eigen::Quaterniond dq = priors[f].q_world_cam.conjugate() * priors[f + 1].q_world_cam;
    const Eigen::Vector3d dp =
        priors[f].q_world_cam.conjugate() * (priors[f + 1].p_world_cam - priors[f].p_world_cam);
    const double dist = dp.norm();
    auto* cost = new ceres::AutoDiffCostFunction<RelativePose, 6, 4, 3, 4, 3>(
        new RelativePose{dq, dp, 1 / (w.rel_sigma_t_m + w.rel_sigma_t_per_m * dist),
                         1 / (w.rel_sigma_r_rad + w.rel_sigma_r_per_m * dist)});
    problem.AddResidualBlock(cost, nullptr, poses[f].q_world_cam.coeffs().data(), poses[f].p_world_cam.data(),
                             poses[f + 1].q_world_cam.coeffs().data(), poses[f + 1].p_world_cam.data());
    ++s.prior_residuals;
  }
  for (size_t f = 0; f < (w.absolute_priors ? n : std::min<size_t>(n, 1)); ++f) {
    if (!variable(f)) continue;
    add_pose(f);
    auto* cost = new ceres::AutoDiffCostFunction<AbsolutePose, 6, 4, 3>(new AbsolutePose{
        priors[f].q_world_cam, priors[f].p_world_cam, 1 / w.gauge_sigma_t_m, 1 / w.gauge_sigma_r_rad});
    problem.AddResidualBlock(cost, w.absolute_priors ? nullptr : new ceres::CauchyLoss(1.0),
                             poses[f].q_world_cam.coeffs().data(), poses[f].p_world_cam.data());
    ++s.prior_residuals;
  }
  if (!w.absolute_priors && w.odometry_sigma_r_rad > 0) {
    double travelled = 0;
    for (size_t f = 0; f < n; ++f) {
      if (f > 0) travelled += (priors[f].p_world_cam - priors[f - 1].p_world_cam).norm();
      if (!variable(f)) continue;
      add_pose(f);
      auto* cost = new ceres::AutoDiffCostFunction<AbsolutePose, 6, 4, 3>(new AbsolutePose{
          priors[f].q_world_cam, priors[f].p_world_cam,
          w.odometry_sigma_t_m > 0 ? 1 / (w.odometry_sigma_t_m + w.odometry_sigma_t_per_m * travelled) : 0.0,
          1 / (w.odometry_sigma_r_rad + w.odometry_sigma_r_per_m * travelled)});
      problem.AddResidualBlock(cost, new ceres::CauchyLoss(1.0), poses[f].q_world_cam.coeffs().data(),
                               poses[f].p_world_cam.data());
      ++s.prior_residuals;
    }
  }
  if (problem.NumResidualBlocks() == 0) {
    s.termination = "EMPTY";
    s.usable = true;
    return s;
  }
  ceres::Solver::Options so;
  so.linear_solver_type = ceres::IsSparseLinearAlgebraLibraryTypeAvailable(ceres::SUITE_SPARSE) ||
                                  ceres::IsSparseLinearAlgebraLibraryTypeAvailable(ceres::EIGEN_SPARSE)
                              ? ceres::SPARSE_SCHUR
                              : ceres::DENSE_SCHUR;
  so.max_num_iterations = b.max_iterations;
  so.num_threads = std::max(1, b.threads);
  so.minimizer_progress_to_stdout = false;
  so.logging_type = ceres::SILENT;
  ceres::Solver::Summary summary;
  ceres::Solve(so, &problem, &summary);
  s.initial_cost = summary.initial_cost;
  s.final_cost = summary.final_cost;
  s.iterations = static_cast<int>(summary.iterations.size());
  s.usable = summary.IsSolutionUsable();
  s.termination = ceres::TerminationTypeToString(summary.termination_type);
  s.brief = summary.BriefReport();
  s.seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  for (auto& pose : poses) pose.q_world_cam.normalize();
  return s;
}

}  // namespace litgs::host::refine
