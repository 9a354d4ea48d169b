#include "calib/extrinsic.h"

#include <ceres/ceres.h>
#include <ceres/rotation.h>

#include <Eigen/Geometry>
#include <algorithm>
#include <cmath>
#include <stdexcept>

#include "io/lens_distortion.h"
#include "io/robust_stats.h"

namespace litgs::calib {
namespace {

// One LiDAR hole centre against its image centre, as an undistorted normalized ray scaled to pixels.
struct CentreReprojection {
  Eigen::Vector3d lidar;
  Eigen::Vector2d ray;  // undistorted normalized image coordinates
  double fx, fy;
  template <typename T>
  bool operator()(const T* const rotation, const T* const translation, T* residual) const {
    const T p[3] = {T(lidar.x()), T(lidar.y()), T(lidar.z())};
    T q[3];
    ceres::AngleAxisRotatePoint(rotation, p, q);
    for (int i = 0; i < 3; ++i) q[i] += translation[i];
    residual[0] = (q[0] / q[2] - T(ray.x())) * T(fx);
    residual[1] = (q[1] / q[2] - T(ray.y())) * T(fy);
    return true;
  }
};

struct Pair {
  size_t view;
  Eigen::Vector3d lidar, camera;  // the hole's centre seen by each sensor
  Eigen::Vector2d ray, px;
};

struct Solution {
  Eigen::Isometry3d T = Eigen::Isometry3d::Identity();
  double rotation_sd_deg = 0, translation_sd_m = 0;
};

Solution solve(const std::vector<Pair>& pairs, const io::CameraIntrinsics& K) {
  Eigen::Matrix3Xd src(3, pairs.size()), dst(3, pairs.size());
  for (size_t i = 0; i < pairs.size(); ++i) {
    src.col(static_cast<Eigen::Index>(i)) = pairs[i].lidar;
    dst.col(static_cast<Eigen::Index>(i)) = pairs[i].camera;
  }
  const Eigen::Matrix4d initial = Eigen::umeyama(src, dst, false);
  const Eigen::AngleAxisd aa(Eigen::Matrix3d(initial.topLeftCorner<3, 3>()));
  double rotation[3], translation[3];
  for (int i = 0; i < 3; ++i) {
    rotation[i] = aa.angle() * aa.axis()(i);
    translation[i] = initial(i, 3);
  }
  ceres::Problem problem;
  for (const Pair& p : pairs)
    problem.AddResidualBlock(new ceres::AutoDiffCostFunction<CentreReprojection, 2, 3, 3>(
                                 new CentreReprojection{p.lidar, p.ray, K.fx, K.fy}),
                             new ceres::HuberLoss(1.0), rotation, translation);
  ceres::Solver::Options options;
  options.max_num_iterations = 100;
  options.function_tolerance = 1e-12;
  options.parameter_tolerance = 1e-12;
  ceres::Solver::Summary summary;
  ceres::Solve(options, &problem, &summary);
  Solution s;
  Eigen::Vector3d r(rotation[0], rotation[1], rotation[2]);
  s.T.linear() = r.norm() > 0 ? Eigen::AngleAxisd(r.norm(), r.normalized()).toRotationMatrix()
                              : Eigen::Matrix3d::Identity();
  s.T.translation() = Eigen::Vector3d(translation[0], translation[1], translation[2]);
  // Standard deviations from the covariance, scaled by the residuals' variance per degree of freedom.
  const double dof = std::max(1.0, 2.0 * static_cast<double>(pairs.size()) - 6);
  const double variance_px = 2 * summary.final_cost / dof;  // the residuals are in pixels
  ceres::Covariance::Options co;
  ceres::Covariance covariance(co);
  std::vector<std::pair<const double*, const double*>> blocks = {{rotation, rotation},
                                                                 {translation, translation}};
  if (covariance.Compute(blocks, &problem)) {
    double cr[9], ct[9];
    covariance.GetCovarianceBlock(rotation, rotation, cr);
    covariance.GetCovarianceBlock(translation, translation, ct);
    s.rotation_sd_deg = std::sqrt(std::max(0.0, (cr[0] + cr[4] + cr[8]) * variance_px)) * 180 / M_PI;
    s.translation_sd_m = std::sqrt(std::max(0.0, (ct[0] + ct[4] + ct[8]) * variance_px));
  }
  return s;
}

}  // namespace

void ExtrinsicOptions::check() const {
  if (min_views < 1) throw std::invalid_argument("min_views must be >= 1");
  if (!(outlier_k > 0)) throw std::invalid_argument("outlier_k must be > 0");
}

ExtrinsicResult solve_extrinsic(const std::vector<ExtrinsicView>& views, const io::CameraIntrinsics& K,
                                const HoledBoard& board, const ExtrinsicOptions& options) {
  options.check();
  board.check();
  ExtrinsicResult result;
  std::vector<Pair> all;
  std::vector<std::string> problems;
  const std::vector<Eigen::Vector3d> layout = board.hole_centres();
  for (size_t v = 0; v < views.size(); ++v) {
    ExtrinsicViewReport report{views[v].name, false, -1, -1, ""};
    const BoardInImage& im = views[v].image;
    const BoardInScan& sc = views[v].scan;
    if (!im.found)
      report.note = "image: " + im.why_not;
    else if (!sc.found)
      report.note = "scan: " + sc.why_not;
    else if (im.centres_px.size() != layout.size() || sc.centres.size() != layout.size())
      report.note = "hole counts differ from the board's";
    if (report.note.empty()) {
      for (size_t k = 0; k < layout.size(); ++k) {
        const auto ray = io::undistort_normalized(
            K, {(im.centres_px[k].x() - K.cx) / K.fx, (im.centres_px[k].y() - K.cy) / K.fy});
        if (!ray) {
          report.note = "image: a hole centre outside the lens model's range";
          break;
        }
        all.push_back({v, sc.centres[k], im.T_cam_board * layout[k], *ray, im.centres_px[k]});
      }
    }
    if (!report.note.empty()) {
      std::erase_if(all, [&](const Pair& p) { return p.view == v; });
      problems.push_back(views[v].name + " (" + report.note + ")");
    }
    result.views.push_back(report);
  }
  const auto usable = [&](const std::vector<Pair>& pairs) {
    std::vector<size_t> seen;
    for (const Pair& p : pairs)
      if (seen.empty() || seen.back() != p.view) seen.push_back(p.view);
    return seen.size();
  };
  if (usable(all) < options.min_views) {
    std::string msg = std::to_string(usable(all)) + " of " + std::to_string(views.size()) +
                      " views show the board to both sensors; at least " + std::to_string(options.min_views) +
                      " are needed";
    for (size_t k = 0; k < problems.size() && k < 6; ++k) msg += (k ? "; " : ": ") + problems[k];
    if (problems.size() > 6) msg += "; ...";
    throw std::invalid_argument(msg);
  }
  const auto view_errors = [&](const Eigen::Isometry3d& T, const std::vector<Pair>& pairs) {
    std::vector<double> px(views.size(), 0), m(views.size(), 0), count(views.size(), 0);
    for (const Pair& p : pairs) {
      const Eigen::Vector3d q = T * p.lidar;
      px[p.view] += (project_to_pixel(K, q) - p.px).squaredNorm();
      m[p.view] += (q - p.camera).squaredNorm();
      count[p.view] += 1;
    }
    for (size_t v = 0; v < views.size(); ++v)
      if (count[v] > 0) {
        result.views[v].rms_px = std::sqrt(px[v] / count[v]);
        result.views[v].rms_m = std::sqrt(m[v] / count[v]);
      }
  };
  Solution s = solve(all, K);
  view_errors(s.T, all);
  // Outlier views left out, then solved again.
  std::vector<double> errors;
  for (const auto& r : result.views)
    if (r.rms_px >= 0) errors.push_back(r.rms_px);
  const double bound = io::robust_upper_bound(errors, options.outlier_k, 1.0);
  std::vector<Pair> kept;
  for (const Pair& p : all)
    if (result.views[p.view].rms_px <= bound) kept.push_back(p);
  if (kept.size() < all.size() && usable(kept) >= options.min_views) {
    for (auto& r : result.views)
      if (r.rms_px > bound)
        r.note = "left out: reprojection RMS " + std::to_string(r.rms_px).substr(0, 5) + " px over " +
                 std::to_string(bound).substr(0, 5) + " px";
    s = solve(kept, K);
    view_errors(s.T, all);
  } else {
    kept = all;
  }
  double px = 0, m = 0;
  for (const Pair& p : kept) {
    const Eigen::Vector3d q = s.T * p.lidar;
    px += (project_to_pixel(K, q) - p.px).squaredNorm();
    m += (q - p.camera).squaredNorm();
    result.views[p.view].used = true;
  }
  result.T_cam_lidar = s.T;
  result.rms_px = std::sqrt(px / static_cast<double>(kept.size()));
  result.rms_m = std::sqrt(m / static_cast<double>(kept.size()));
  result.rotation_sd_deg = s.rotation_sd_deg;
  result.translation_sd_m = s.translation_sd_m;
  result.views_used = usable(kept);
  return result;
}

}  // namespace litgs::calib
