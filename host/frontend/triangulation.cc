#include "host/frontend/triangulation.h"

#include <Eigen/Dense>
#include <algorithm>
#include <cmath>
#include <limits>
#include <numeric>
#include <stdexcept>

namespace litgs::host::frontend {
namespace {

constexpr double kNaN = std::numeric_limits<double>::quiet_NaN();

double error_px(const TriangulationView& v, const Eigen::Vector3d& X, double fx, double fy) {
  const Eigen::Vector3d c = v.R_cam_world * X + v.t_cam_world;
  if (!(c.z() > 0)) return std::numeric_limits<double>::infinity();
  return std::hypot((c.x() / c.z() - v.xy.x()) * fx, (c.y() / c.z() - v.xy.y()) * fy);
}

// The views whose reprojection error of X is below max_error_px; `sum` gets their errors' sum.
std::vector<size_t> agreeing_views(const std::vector<TriangulationView>& views, const Eigen::Vector3d& X,
                                   double fx, double fy, double max_error_px, double& sum) {
  std::vector<size_t> agree;
  sum = 0;
  for (size_t k = 0; k < views.size(); ++k) {
    const double e = error_px(views[k], X, fx, fy);
    if (e < max_error_px) {
      agree.push_back(k);
      sum += e;
    }
  }
  return agree;
}

Eigen::Vector3d centre(const TriangulationView& v) {
  return -v.R_cam_world.transpose() * v.t_cam_world;
}

// Largest angle (degrees) between the rays from the views' centres to X.
double max_angle_deg(const std::vector<TriangulationView>& views, const std::vector<size_t>& use,
                     const Eigen::Vector3d& X) {
  double best = 0;
  for (size_t i = 0; i < use.size(); ++i)
    for (size_t j = i + 1; j < use.size(); ++j) {
      const Eigen::Vector3d a = (X - centre(views[use[i]])).normalized();
      const Eigen::Vector3d b = (X - centre(views[use[j]])).normalized();
      best = std::max(best, std::atan2(a.cross(b).norm(), a.dot(b)) * 180.0 / M_PI);
    }
  return best;
}

// Gauss-Newton on the normalized reprojection residuals weighted to pixels.
Eigen::Vector3d refine(const std::vector<TriangulationView>& views, const std::vector<size_t>& use,
                       Eigen::Vector3d X, double fx, double fy, int iterations) {
  for (int it = 0; it < iterations; ++it) {
    Eigen::Matrix3d H = Eigen::Matrix3d::Zero();
    Eigen::Vector3d g = Eigen::Vector3d::Zero();
    for (size_t k : use) {
      const TriangulationView& v = views[k];
      const Eigen::Vector3d c = v.R_cam_world * X + v.t_cam_world;
      if (!(c.z() > 0)) return X;
      const double iz = 1.0 / c.z();
      Eigen::Matrix<double, 2, 3> Jc;
      Jc << fx * iz, 0, -fx * c.x() * iz * iz, 0, fy * iz, -fy * c.y() * iz * iz;
      const Eigen::Matrix<double, 2, 3> J = Jc * v.R_cam_world;
      const Eigen::Vector2d r((c.x() * iz - v.xy.x()) * fx, (c.y() * iz - v.xy.y()) * fy);
      H += J.transpose() * J;
      g += J.transpose() * r;
    }
    const Eigen::Vector3d step = H.ldlt().solve(-g);
    if (!step.allFinite()) return X;
    X += step;
    if (step.norm() < 1e-12 * (1 + X.norm())) break;
  }
  return X;
}

// The two-view or fitted point of the configured estimator.
Eigen::Vector3d estimate(const std::vector<TriangulationView>& views, const std::vector<size_t>& use,
                         const TriangulationOptions& o) {
  return o.method == TriangulationMethod::kMidpoint ? triangulate_midpoint(views, use)
                                                    : triangulate_linear(views, use);
}

struct Candidate {
  size_t i, j;
  double cos_angle;  // between the observed rays in the world
};

// Candidate pairs in the configured order, at most max_pairs_tried; `widest_cos` gets the cosine of the
// widest observed ray angle over all pairs.
std::vector<Candidate> candidate_pairs(const std::vector<TriangulationView>& views,
                                       const TriangulationOptions& o, double& widest_cos) {
  std::vector<Eigen::Vector3d> rays(views.size());
  for (size_t k = 0; k < views.size(); ++k)
    rays[k] = (views[k].R_cam_world.transpose() * views[k].xy.homogeneous()).normalized();
  std::vector<Candidate> candidates;
  widest_cos = 1;
  for (size_t i = 0; i < views.size(); ++i)
    for (size_t j = i + 1; j < views.size(); ++j) {
      candidates.push_back({i, j, rays[i].dot(rays[j])});
      widest_cos = std::min(widest_cos, candidates.back().cos_angle);
    }
  if (o.pair_order == PairOrder::kWidestRayAngle) {
    std::stable_sort(candidates.begin(), candidates.end(),
                     [](const Candidate& a, const Candidate& b) { return a.cos_angle < b.cos_angle; });
  } else {
    // First with last, then inwards: the widest index gaps first.
    std::stable_sort(candidates.begin(), candidates.end(),
                     [](const Candidate& a, const Candidate& b) { return a.j - a.i > b.j - b.i; });
  }
  candidates.resize(std::min(candidates.size(), o.max_pairs_tried));
  return candidates;
}

}  // namespace

TriangulationOptions TriangulationOptions::refinement() {
  TriangulationOptions o;
  o.method = TriangulationMethod::kMidpoint;
  o.pair_order = PairOrder::kSpreadOverViews;
  o.max_error_px = 4;
  o.min_views = 2;
  o.min_angle_deg = 1.0;
  o.gauss_newton_iterations = 0;
  o.max_pairs_tried = 12;
  return o;
}

void TriangulationOptions::check() const {
  if (!(max_error_px > 0)) throw std::invalid_argument("triangulation: max_error_px must be > 0");
  if (!(min_angle_deg >= 0 && min_angle_deg < 90))
    throw std::invalid_argument("triangulation: min_angle_deg must be in [0, 90)");
  if (!(min_depth_m >= 0 && max_depth_m > min_depth_m))
    throw std::invalid_argument("triangulation: need 0 <= min_depth_m < max_depth_m");
  if (min_views < 2) throw std::invalid_argument("triangulation: min_views must be >= 2");
  if (gauss_newton_iterations < 0) throw std::invalid_argument("triangulation: gauss_newton_iterations >= 0");
  if (max_pairs_tried < 1) throw std::invalid_argument("triangulation: max_pairs_tried >= 1");
}

Eigen::Vector3d triangulate_linear(const std::vector<TriangulationView>& views,
                                   const std::vector<size_t>& use) {
  if (use.size() < 2) return Eigen::Vector3d::Constant(kNaN);
  Eigen::MatrixXd A(2 * use.size(), 4);
  for (size_t r = 0; r < use.size(); ++r) {
    const TriangulationView& v = views[use[r]];
    Eigen::Matrix<double, 3, 4> P;
    P << v.R_cam_world, v.t_cam_world;
    A.row(2 * r) = v.xy.x() * P.row(2) - P.row(0);
    A.row(2 * r + 1) = v.xy.y() * P.row(2) - P.row(1);
  }
  const Eigen::JacobiSVD<Eigen::MatrixXd> svd(A, Eigen::ComputeFullV);
  const Eigen::Vector4d h = svd.matrixV().col(3);
  if (!(std::abs(h.w()) > 1e-12 * h.head<3>().norm())) return Eigen::Vector3d::Constant(kNaN);
  return h.head<3>() / h.w();
}

Eigen::Vector3d triangulate_midpoint(const std::vector<TriangulationView>& views,
                                     const std::vector<size_t>& use) {
  if (use.size() < 2) return Eigen::Vector3d::Constant(kNaN);
  // Sum over the rays of (I - d d^T)(X - c) = 0.
  Eigen::Matrix3d A = Eigen::Matrix3d::Zero();
  Eigen::Vector3d b = Eigen::Vector3d::Zero();
  for (size_t k : use) {
    const TriangulationView& v = views[k];
    const Eigen::Vector3d d = (v.R_cam_world.transpose() * v.xy.homogeneous()).normalized();
    const Eigen::Matrix3d P = Eigen::Matrix3d::Identity() - d * d.transpose();
    A += P;
    b += P * centre(v);
  }
  const Eigen::LDLT<Eigen::Matrix3d> ldlt(A);
  if (ldlt.info() != Eigen::Success) return Eigen::Vector3d::Constant(kNaN);
  return ldlt.solve(b);
}

TriangulatedPoint triangulate(const std::vector<TriangulationView>& views, double fx, double fy,
                              const TriangulationOptions& o) {
  o.check();
  TriangulatedPoint out;
  if (views.size() < o.min_views) return out;
  double widest_cos = 1;
  const std::vector<Candidate> candidates = candidate_pairs(views, o, widest_cos);
  // Rays that never part by the minimum angle (a pure rotation, a distant point): nothing to triangulate.
  if (widest_cos > std::cos(o.min_angle_deg * M_PI / 180.0)) {
    out.outcome = TriangulationOutcome::kNoAngle;
    return out;
  }

  std::vector<size_t> best_views;
  double best_sum = 0;
  Eigen::Vector3d best_X = Eigen::Vector3d::Constant(kNaN);
  for (const Candidate& c : candidates) {
    const Eigen::Vector3d X = estimate(views, {c.i, c.j}, o);
    if (!X.allFinite()) continue;
    double sum = 0;
    const std::vector<size_t> agree = agreeing_views(views, X, fx, fy, o.max_error_px, sum);
    if (agree.size() > best_views.size() || (agree.size() == best_views.size() && sum < best_sum)) {
      best_views = agree;
      best_sum = sum;
      best_X = X;
    }
  }
  if (best_views.size() < o.min_views) {
    out.outcome = best_X.allFinite() ? TriangulationOutcome::kLargeError : TriangulationOutcome::kNoAngle;
    return out;
  }
  // Fit over the agreeing views, refine, and take the views that agree with the refined point.
  Eigen::Vector3d X = estimate(views, best_views, o);
  if (!X.allFinite()) X = best_X;
  X = refine(views, best_views, X, fx, fy, o.gauss_newton_iterations);
  double sum = 0;
  std::vector<size_t> agree = agreeing_views(views, X, fx, fy, o.max_error_px, sum);
  if (!X.allFinite() || agree.size() < o.min_views) {
    out.outcome = TriangulationOutcome::kLargeError;
    return out;
  }
  for (size_t k : agree) {
    const double depth = (views[k].R_cam_world * X + views[k].t_cam_world).z();
    if (!(depth >= o.min_depth_m && depth <= o.max_depth_m)) {
      out.outcome = TriangulationOutcome::kBadDepth;
      return out;
    }
  }
  if (!(max_angle_deg(views, agree, X) >= o.min_angle_deg)) {
    out.outcome = TriangulationOutcome::kNoAngle;
    return out;
  }
  out.outcome = TriangulationOutcome::kOk;
  out.xyz = X;
  out.views = std::move(agree);
  out.mean_error_px = sum / static_cast<double>(out.views.size());
  return out;
}

}  // namespace litgs::host::frontend
