#include "host/refine/weights.h"

#include <Eigen/Eigenvalues>
#include <algorithm>
#include <cmath>
#include <limits>
#include <stdexcept>

#include "io/robust_stats.h"

namespace litgs::host::refine {

namespace {

// (x - median) / (1.4826 MAD), with the scale floored at `floor` so that a constant sequence gives zeros.
std::vector<double> standardize(const std::vector<double>& x, double floor) {
  const double m = io::median(x);
  std::vector<double> dev;
  for (double v : x) dev.push_back(std::abs(v - m));
  const double scale = std::max(1.4826 * io::median(dev), floor);
  std::vector<double> z;
  for (double v : x) z.push_back((v - m) / scale);
  return z;
}

}  // namespace

void WeightOptions::check() const {
  if (!(alpha_min >= 0 && alpha_min <= alpha_max && alpha_max <= 1))
    throw std::invalid_argument("alpha: need 0 <= alpha_min <= alpha_max <= 1 (got " +
                                std::to_string(alpha_min) + ", " + std::to_string(alpha_max) + ")");
  if (!(min_sigma_m > 0)) throw std::invalid_argument("WeightOptions.min_sigma_m must be > 0");
  if (!(proximity_px > 0)) throw std::invalid_argument("WeightOptions.proximity_px must be > 0");
}

std::vector<double> motion_scores(const std::vector<CameraPose>& poses) {
  const size_t n = poses.size();
  if (n < 2) return std::vector<double>(n, 0.0);
  std::vector<double> lin(n), ang(n);
  for (size_t i = 0; i < n; ++i) {
    const size_t a = i == 0 ? 0 : i - 1, b = i + 1 == n ? n - 1 : i + 1;
    const double dt = std::max(poses[b].t_s - poses[a].t_s, 1e-9);
    lin[i] = (poses[b].p_world_cam - poses[a].p_world_cam).norm() / dt;
    ang[i] = poses[a].q_world_cam.angularDistance(poses[b].q_world_cam) / dt;
  }
  const std::vector<double> zl = standardize(lin, 1e-3), za = standardize(ang, 1e-3);
  std::vector<double> s(n);
  for (size_t i = 0; i < n; ++i) s[i] = 0.5 * (zl[i] + za[i]);
  return s;
}

std::vector<double> motion_alphas(const std::vector<double>& scores, const WeightOptions& o) {
  o.check();
  std::vector<double> a;
  for (double s : scores) a.push_back(o.alpha_min + (o.alpha_max - o.alpha_min) / (1 + std::exp(-s)));
  return a;
}

Eigen::Matrix3d guarded_covariance(const Eigen::Matrix3d& cov, double floor_m2, bool* raised) {
  const Eigen::SelfAdjointEigenSolver<Eigen::Matrix3d> eig(0.5 * (cov + cov.transpose()));
  Eigen::Vector3d ev = eig.eigenvalues();
  bool any = false;
  for (int i = 0; i < 3; ++i)
    if (!(ev[i] >= floor_m2)) {  // NaN too
      ev[i] = floor_m2;
      any = true;
    }
  if (raised) *raised = any;
  return eig.eigenvectors() * ev.asDiagonal() * eig.eigenvectors().transpose();
}

AnchorWeights anchor_weights(const std::vector<AnchorPoint>& anchors, const WeightOptions& o) {
  o.check();
  AnchorWeights w;
  std::vector<double> raw;
  for (const auto& a : anchors) {
    bool raised = false;
    const Eigen::Matrix3d c = guarded_covariance(a.cov, o.min_sigma_m * o.min_sigma_m, &raised);
    w.guarded += raised;
    raw.push_back(1.0 / std::sqrt(c.determinant()));
  }
  w.median_raw = io::median(raw);
  for (double r : raw) w.weights.push_back(w.median_raw > 0 ? r / w.median_raw : 1.0);
  return w;
}

void assign_observation_weights(std::vector<TrackPoint>& points, const std::vector<double>& alphas,
                                const std::vector<double>& anchor_weight, const WeightOptions& o) {
  o.check();
  struct Ref {
    TrackPoint* point;
    Observation* obs;
  };
  std::vector<std::vector<Ref>> per_frame(alphas.size());
  for (auto& p : points) {
    if (!p.active) continue;
    for (auto& ob : p.obs) {
      ob.weight = 1;
      if (ob.active && ob.frame < per_frame.size()) per_frame[ob.frame].push_back({&p, &ob});
    }
  }
  for (size_t f = 0; f < per_frame.size(); ++f) {
    std::vector<Ref> anchored, others;
    for (const auto& r : per_frame[f]) (r.point->anchor >= 0 ? anchored : others).push_back(r);
    if (anchored.empty() || others.empty()) continue;
    const double total = static_cast<double>(per_frame[f].size());
    double sum_a = 0;
    for (const auto& r : anchored) sum_a += anchor_weight.at(static_cast<size_t>(r.point->anchor));
    for (const auto& r : anchored)
      r.obs->weight = alphas[f] * total * anchor_weight[static_cast<size_t>(r.point->anchor)] / sum_a;
    std::vector<double> prox;
    double sum_p = 0;
    for (const auto& r : others) {
      double d = std::numeric_limits<double>::infinity();
      for (const auto& a : anchored) d = std::min(d, (a.obs->uv - r.obs->uv).norm());
      prox.push_back(1.0 / (1.0 + d / o.proximity_px));
      sum_p += prox.back();
    }
    for (size_t i = 0; i < others.size(); ++i)
      others[i].obs->weight = (1 - alphas[f]) * total * prox[i] / sum_p;
  }
}

}  // namespace litgs::host::refine
