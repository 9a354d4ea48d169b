#include "calib/layout_fit.h"

#include <Eigen/Geometry>
#include <cmath>
#include <limits>

#include "calib/holed_board.h"

namespace litgs::calib {

std::vector<std::vector<size_t>> cyclic_correspondences(const std::vector<Eigen::Vector2d>& holes,
                                                        const std::vector<Eigen::Vector2d>& detections) {
  std::vector<std::vector<size_t>> out;
  if (holes.size() != detections.size() || holes.empty()) return out;
  const std::vector<size_t> hole_order = cyclic_hole_order(holes);
  const std::vector<size_t> detection_order = cyclic_hole_order(detections);
  const size_t n = holes.size();
  for (size_t s = 0; s < n; ++s) {
    std::vector<size_t> detection_of_hole(n);
    for (size_t i = 0; i < n; ++i) detection_of_hole[hole_order[(i + s) % n]] = detection_order[i];
    out.push_back(detection_of_hole);
  }
  return out;
}

LayoutFit fit_layout_2d(const std::vector<Eigen::Vector2d>& holes,
                        const std::vector<Eigen::Vector2d>& detections) {
  LayoutFit best;
  const auto candidates = cyclic_correspondences(holes, detections);
  if (candidates.empty()) {
    best.why_not =
        std::to_string(detections.size()) + " holes detected, the board has " + std::to_string(holes.size());
    return best;
  }
  std::vector<LayoutFit> fits;
  double least = std::numeric_limits<double>::infinity();
  for (const auto& match : candidates) {
    const size_t n = holes.size();
    Eigen::Vector2d hm = Eigen::Vector2d::Zero(), dm = Eigen::Vector2d::Zero();
    for (size_t k = 0; k < n; ++k) {
      hm += holes[k];
      dm += detections[match[k]];
    }
    hm /= static_cast<double>(n);
    dm /= static_cast<double>(n);
    double cross = 0, dot = 0;
    for (size_t k = 0; k < n; ++k) {
      const Eigen::Vector2d h = holes[k] - hm, d = detections[match[k]] - dm;
      cross += h.x() * d.y() - h.y() * d.x();
      dot += h.x() * d.x() + h.y() * d.y();
    }
    LayoutFit f;
    f.ok = true;
    f.detection_of_hole = match;
    f.angle_rad = std::atan2(cross, dot);
    const Eigen::Rotation2Dd R(f.angle_rad);
    double sq = 0;
    for (size_t k = 0; k < n; ++k) {
      f.placed.push_back(R * (holes[k] - hm) + dm);
      sq += (f.placed.back() - detections[match[k]]).squaredNorm();
    }
    f.rms = std::sqrt(sq / static_cast<double>(n));
    least = std::min(least, f.rms);
    fits.push_back(f);
  }
  // Among the shifts that fit about as well as the best (a symmetric board), the most upright.
  double smallest_turn = std::numeric_limits<double>::infinity();
  for (const LayoutFit& f : fits)
    if (f.rms <= 1.5 * least + 1e-9 && std::abs(f.angle_rad) < smallest_turn) {
      smallest_turn = std::abs(f.angle_rad);
      best = f;
    }
  return best;
}

}  // namespace litgs::calib
