#include "host/refine/ate.h"

#include <Eigen/Geometry>
#include <algorithm>
#include <cmath>
#include <stdexcept>

namespace litgs::host::refine {

Similarity umeyama_alignment(const std::vector<Eigen::Vector3d>& src, const std::vector<Eigen::Vector3d>& dst,
                             bool with_scale) {
  if (src.size() != dst.size()) throw std::invalid_argument("umeyama_alignment: point counts differ");
  if (src.size() < 3) throw std::invalid_argument("umeyama_alignment: needs at least 3 point pairs");
  Eigen::Matrix3Xd a(3, src.size()), b(3, dst.size());
  for (size_t i = 0; i < src.size(); ++i) {
    a.col(static_cast<Eigen::Index>(i)) = src[i];
    b.col(static_cast<Eigen::Index>(i)) = dst[i];
  }
  const Eigen::Matrix4d T = Eigen::umeyama(a, b, with_scale);
  Similarity out;
  out.s = with_scale ? std::cbrt(T.topLeftCorner<3, 3>().determinant()) : 1.0;
  out.R = T.topLeftCorner<3, 3>() / out.s;
  out.t = T.topRightCorner<3, 1>();
  return out;
}

AteResult absolute_trajectory_error(const std::vector<io::TumPose>& estimate,
                                    const std::vector<io::TumPose>& truth, AteAlignment alignment,
                                    double max_dt_s) {
  std::vector<Eigen::Vector3d> est, gt;
  for (const auto& g : truth) {
    const auto it = std::lower_bound(estimate.begin(), estimate.end(), g.t_s,
                                     [](const io::TumPose& p, double t) { return p.t_s < t; });
    const io::TumPose* best = nullptr;
    for (auto c : {it, it == estimate.begin() ? it : it - 1})
      if (c != estimate.end() && std::abs(c->t_s - g.t_s) <= max_dt_s &&
          (!best || std::abs(c->t_s - g.t_s) < std::abs(best->t_s - g.t_s)))
        best = &*c;
    if (!best) continue;
    est.push_back(best->p_world);
    gt.push_back(g.p_world);
  }
  if (est.size() < 3)
    throw std::invalid_argument("ATE: only " + std::to_string(est.size()) +
                                " estimate poses match a truth pose in time (need 3)");
  AteResult r;
  r.pairs = est.size();
  if (alignment != AteAlignment::kNone)
    r.alignment = umeyama_alignment(est, gt, alignment == AteAlignment::kSim3);
  double sum2 = 0, sum = 0;
  for (size_t i = 0; i < est.size(); ++i) {
    const double e = (r.alignment.apply(est[i]) - gt[i]).norm();
    sum2 += e * e;
    sum += e;
    r.max_m = std::max(r.max_m, e);
  }
  r.rmse_m = std::sqrt(sum2 / static_cast<double>(est.size()));
  r.mean_m = sum / static_cast<double>(est.size());
  return r;
}

std::vector<io::TumPose> as_tum_poses(const std::vector<CameraPose>& poses) {
  std::vector<io::TumPose> out;
  out.reserve(poses.size());
  for (const auto& c : poses) {
    io::TumPose p;
    p.t_s = c.t_s;
    p.p_world = c.p_world_cam;
    p.q_world_body = c.q_world_cam;
    out.push_back(p);
  }
  return out;
}

}  // namespace litgs::host::refine
