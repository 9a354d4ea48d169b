#include "host/frontend/verification.h"

#include <Eigen/Geometry>
#include <algorithm>
#include <cmath>
#include <opencv2/calib3d.hpp>
#include <stdexcept>

namespace litgs::host::frontend {

std::vector<Eigen::Vector2d> undistort_keypoints(const io::CameraIntrinsics& k,
                                                 const std::vector<io::SfmKeypoint>& keypoints) {
  std::vector<Eigen::Vector2d> out(keypoints.size());
  if (keypoints.empty()) return out;
  std::vector<cv::Point2f> src, dst;
  for (const auto& kp : keypoints) src.emplace_back(kp.x, kp.y);
  const cv::Matx33d K(k.fx, 0, k.cx, 0, k.fy, k.cy, 0, 0, 1);
  if (k.distortion.empty()) {
    dst = src;
  } else if (k.model == io::CameraModel::kEquidistant) {
    std::vector<double> d(k.distortion);
    d.resize(4, 0.0);
    cv::fisheye::undistortPoints(src, dst, K, d, cv::noArray(), K);
  } else {
    cv::undistortPoints(src, dst, K, k.distortion, cv::noArray(), K);
  }
  for (size_t i = 0; i < dst.size(); ++i) out[i] = {dst[i].x, dst[i].y};
  return out;
}

void VerifyOptions::check() const {
  if (!(max_error_px > 0)) throw std::invalid_argument("verify: max_error_px must be > 0");
  if (!(confidence > 0 && confidence < 1))
    throw std::invalid_argument("verify: confidence must be in (0, 1)");
  if (max_iterations < 1) throw std::invalid_argument("verify: max_iterations must be >= 1");
  if (!(prior_epipolar_px > 0)) throw std::invalid_argument("verify: prior_epipolar_px must be > 0");
  if (min_inliers < 5)
    throw std::invalid_argument("verify: min_inliers must be >= 5 (the five-point solver)");
}

double prior_distance_px(const Eigen::Vector2d& xa, const Eigen::Vector2d& xb, const PinholeK& K,
                         const RelativePose& prior) {
  const Eigen::Vector3d a((xa.x() - K.cx) / K.fx, (xa.y() - K.cy) / K.fy, 1.0);
  const Eigen::Vector3d b((xb.x() - K.cx) / K.fx, (xb.y() - K.cy) / K.fy, 1.0);
  const double baseline = prior.t_ba.norm();
  if (!(baseline > 1e-12)) {  // no baseline: b must be a rotated
    const Eigen::Vector3d r = prior.R_ba * a;
    if (!(r.z() > 1e-12)) return INFINITY;
    return std::hypot((r.x() / r.z() - b.x()) * K.fx, (r.y() / r.z() - b.y()) * K.fy);
  }
  const Eigen::Vector3d t = prior.t_ba / baseline;
  Eigen::Matrix3d tx;
  tx << 0, -t.z(), t.y(), t.z(), 0, -t.x(), -t.y(), t.x(), 0;
  const Eigen::Matrix3d E = tx * prior.R_ba;  // b^T E a = 0
  // Line distances in normalized coordinates, scaled to pixels by the mean focal length.
  const double f = 0.5 * (K.fx + K.fy);
  const Eigen::Vector3d lb = E * a, la = E.transpose() * b;
  const double residual = std::abs(b.dot(lb));
  const double db = residual / std::max(std::hypot(lb.x(), lb.y()), 1e-300);
  const double da = residual / std::max(std::hypot(la.x(), la.y()), 1e-300);
  return f * std::max(da, db);
}

std::vector<std::vector<uint32_t>> prior_candidates(const std::vector<Eigen::Vector2d>& ua,
                                                    const std::vector<Eigen::Vector2d>& ub, const PinholeK& K,
                                                    const RelativePose& prior, double bound_px) {
  std::vector<std::vector<uint32_t>> out(ua.size());
  const double baseline = prior.t_ba.norm();
  if (!(baseline > 1e-12)) {  // no baseline: the general (point transfer) distance for every pair
    for (size_t i = 0; i < ua.size(); ++i)
      for (size_t j = 0; j < ub.size(); ++j)
        if (prior_distance_px(ua[i], ub[j], K, prior) <= bound_px) out[i].push_back(static_cast<uint32_t>(j));
    return out;
  }
  // Epipolar lines in pixels, scaled so that |line . (x, y, 1)| is the distance in normalized units times
  // the mean focal length: the same measure as prior_distance_px, computed once per keypoint.
  auto normalized = [&](const Eigen::Vector2d& x) {
    return Eigen::Vector3d((x.x() - K.cx) / K.fx, (x.y() - K.cy) / K.fy, 1.0);
  };
  const Eigen::Vector3d t = prior.t_ba / baseline;
  Eigen::Matrix3d tx;
  tx << 0, -t.z(), t.y(), t.z(), 0, -t.x(), -t.y(), t.x(), 0;
  const Eigen::Matrix3d E = tx * prior.R_ba;
  const double f = 0.5 * (K.fx + K.fy);
  std::vector<Eigen::Vector3d> na(ua.size()), nb(ub.size()), line_in_a(ub.size());
  for (size_t j = 0; j < ub.size(); ++j) {
    nb[j] = normalized(ub[j]);
    const Eigen::Vector3d l = E.transpose() * nb[j];
    line_in_a[j] = f * l / std::max(std::hypot(l.x(), l.y()), 1e-300);
  }
  // b's keypoints in a grid of kCell-pixel cells: each line visits only the cells its band crosses.
  constexpr double kCell = 16;
  Eigen::Vector2d lo_corner = Eigen::Vector2d::Constant(INFINITY), hi_corner = -lo_corner;
  for (const auto& x : ub)
    if (x.allFinite()) {
      lo_corner = lo_corner.cwiseMin(x);
      hi_corner = hi_corner.cwiseMax(x);
    }
  if (!lo_corner.allFinite()) return out;
  const Eigen::Vector2d extent = hi_corner - lo_corner;
  const auto cols = static_cast<int>(std::clamp(extent.x() / kCell + 1, 1.0, 4096.0));
  const auto rows = static_cast<int>(std::clamp(extent.y() / kCell + 1, 1.0, 4096.0));
  std::vector<std::vector<uint32_t>> cells(static_cast<size_t>(cols) * rows);
  auto cell_of = [&](double v, int n) {
    return std::clamp(static_cast<int>(std::floor(v / kCell)), 0, n - 1);
  };
  for (size_t j = 0; j < ub.size(); ++j) {
    if (!ub[j].allFinite()) continue;
    const Eigen::Vector2d p = ub[j] - lo_corner;
    cells[static_cast<size_t>(cell_of(p.y(), rows)) * cols + cell_of(p.x(), cols)].push_back(
        static_cast<uint32_t>(j));
  }
  for (size_t i = 0; i < ua.size(); ++i) {
    na[i] = normalized(ua[i]);
    const Eigen::Vector3d l = E * na[i];
    const Eigen::Vector3d line = f * l / std::max(std::hypot(l.x(), l.y()), 1e-300);
    auto visit = [&](int cx, int cy) {
      for (uint32_t j : cells[static_cast<size_t>(cy) * cols + cx])
        if (std::abs(line.dot(nb[j])) <= bound_px && std::abs(line_in_a[j].dot(na[i])) <= bound_px)
          out[i].push_back(j);
    };
    // The band as A x + B y + C in pixels relative to the grid's corner: |A x + B y + C| <= bound_px.
    const double A = line.x() / K.fx, B = line.y() / K.fy;
    const double C = line.z() - A * (K.cx - lo_corner.x()) - B * (K.cy - lo_corner.y());
    if (!std::isfinite(A) || !std::isfinite(B) || !std::isfinite(C) || (A == 0 && B == 0)) continue;
    const bool flat = std::abs(B) >= std::abs(A);  // walk along x (flat lines) or along y (steep ones)
    const int n_walk = flat ? cols : rows, n_across = flat ? rows : cols;
    const double along = flat ? B : A, other = flat ? A : B;
    const double half = bound_px / std::abs(along);  // the band's half width across the walk direction
    for (int w = 0; w < n_walk; ++w) {
      // The band's extent across, over this column (row) of cells.
      const double v0 = -(other * w * kCell + C) / along, v1 = -(other * (w + 1) * kCell + C) / along;
      const double lo = std::min(v0, v1) - half, hi = std::max(v0, v1) + half;
      if (hi < 0 || lo > n_across * kCell) continue;  // every keypoint lies in [0, n_across * kCell)
      for (int a = cell_of(lo, n_across); a <= cell_of(hi, n_across); ++a) flat ? visit(w, a) : visit(a, w);
    }
  }
  return out;
}

Verification verify_pair(const std::vector<Eigen::Vector2d>& ua, const std::vector<Eigen::Vector2d>& ub,
                         const std::vector<std::array<uint32_t, 2>>& matches, const PinholeK& K,
                         const std::optional<RelativePose>& prior, const VerifyOptions& o) {
  o.check();
  Verification v;
  v.inlier.assign(matches.size(), 0);
  // The prior's bound first: it removes gross outliers before the robust fit.
  std::vector<size_t> candidates;
  for (size_t m = 0; m < matches.size(); ++m) {
    const Eigen::Vector2d& xa = ua.at(matches[m][0]);
    const Eigen::Vector2d& xb = ub.at(matches[m][1]);
    if (!xa.allFinite() || !xb.allFinite()) continue;
    if (prior && !(prior_distance_px(xa, xb, K, *prior) <= o.prior_epipolar_px)) {
      ++v.rejected_by_prior;
      continue;
    }
    candidates.push_back(m);
  }
  if (candidates.size() < o.min_inliers) return v;
  std::vector<cv::Point2d> pa, pb;
  for (size_t m : candidates) {
    pa.emplace_back(ua[matches[m][0]].x(), ua[matches[m][0]].y());
    pb.emplace_back(ub[matches[m][1]].x(), ub[matches[m][1]].y());
  }
  const cv::Matx33d Kcv(K.fx, 0, K.cx, 0, K.fy, K.cy, 0, 0, 1);
  cv::Mat mask;
  cv::Mat E;
  try {
    E = cv::findEssentialMat(pa, pb, Kcv, cv::USAC_MAGSAC, o.confidence, o.max_error_px, o.max_iterations,
                             mask);
  } catch (const cv::Exception&) {
    return v;  // degenerate sample sets (e.g. all matches on one point): nothing verified
  }
  if (E.empty() || mask.empty()) return v;
  size_t count = 0;
  for (size_t i = 0; i < candidates.size(); ++i) count += mask.at<uint8_t>(static_cast<int>(i)) != 0;
  if (count < o.min_inliers) return v;
  for (size_t i = 0; i < candidates.size(); ++i)
    if (mask.at<uint8_t>(static_cast<int>(i))) v.inlier[candidates[i]] = 1;
  v.inliers = count;
  v.verified = true;
  return v;
}

}  // namespace litgs::host::frontend
