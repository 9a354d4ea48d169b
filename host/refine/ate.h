// Absolute trajectory error, the convention of evo: positions of the estimate aligned to the truth by the
// least-squares rigid (SE(3)) or similarity (Sim(3)) transform (Umeyama), then the RMSE of the distances.
// Only positions enter, so a truth without rotations (M2DGR's Leica tracker) is handled the same way.
#pragma once

#include <Eigen/Core>
#include <vector>

#include "host/refine/ba_types.h"
#include "io/tum.h"

namespace litgs::host::refine {

struct Similarity {
  Eigen::Matrix3d R = Eigen::Matrix3d::Identity();
  Eigen::Vector3d t = Eigen::Vector3d::Zero();
  double s = 1;
  Eigen::Vector3d apply(const Eigen::Vector3d& x) const { return s * (R * x) + t; }
};

// The transform minimizing sum |dst_i - (s R src_i + t)|^2 (s = 1 unless with_scale). Needs >= 3 points
// not on one line for a unique rotation; std::invalid_argument on fewer than 3 or on sizes that differ.
Similarity umeyama_alignment(const std::vector<Eigen::Vector3d>& src, const std::vector<Eigen::Vector3d>& dst,
                             bool with_scale);

enum class AteAlignment { kSE3, kSim3, kNone };

struct AteResult {
  double rmse_m = 0, mean_m = 0, max_m = 0;
  size_t pairs = 0;  // estimate/truth pairs matched by time
  Similarity alignment;
};

// Pairs each truth pose with the estimate at the same time (within max_dt_s, nearest), aligns, and
// measures. std::invalid_argument when fewer than 3 pairs match.
AteResult absolute_trajectory_error(const std::vector<io::TumPose>& estimate,
                                    const std::vector<io::TumPose>& truth, AteAlignment alignment,
                                    double max_dt_s = 0.01);

// Camera poses as TUM poses (time, position, rotation; no change of frame).
std::vector<io::TumPose> as_tum_poses(const std::vector<CameraPose>& poses);

}  // namespace litgs::host::refine
