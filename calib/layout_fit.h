// Which detected hole is which: both sensors see the board from the front (x right, y down), so their
// detections and the board's holes share one cyclic order; the correspondence is the cyclic shift whose
// rigid fit leaves the least residual, and on a symmetric board (several shifts fit alike) the one that
// turns the board least from upright.
#pragma once

#include <Eigen/Core>
#include <string>
#include <vector>

namespace litgs::calib {

struct LayoutFit {
  bool ok = false;
  std::string why_not;
  std::vector<size_t> detection_of_hole;  // [holes]: the detection matched to hole k
  std::vector<Eigen::Vector2d> placed;    // [holes]: hole k placed by the fitted rotation and translation
  double angle_rad = 0;                   // the fitted in-plane rotation
  double rms = 0;                         // detections against the placed holes
};

// Candidate correspondences in the shared cyclic order: shift s pairs the i-th detection with the
// (i + s)-th hole. Fewer or more detections than holes: not ok.
std::vector<std::vector<size_t>> cyclic_correspondences(const std::vector<Eigen::Vector2d>& holes,
                                                        const std::vector<Eigen::Vector2d>& detections);

// 2D rigid fit (Procrustes) of the board's holes to detections in the board's plane (metres).
LayoutFit fit_layout_2d(const std::vector<Eigen::Vector2d>& holes,
                        const std::vector<Eigen::Vector2d>& detections);

}  // namespace litgs::calib
