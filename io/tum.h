// TUM trajectories: one pose per line, "t x y z qx qy qz qw" (seconds, metres, Hamilton quaternion).
// A pose maps points of the moving frame into the world: (x y z, q) is T_world_body.
#pragma once

#include <Eigen/Core>
#include <Eigen/Geometry>
#include <filesystem>
#include <optional>
#include <vector>

namespace litgs::io {

struct TumPose {
  double t_s = 0;                                                    // timestamp, seconds
  Eigen::Vector3d p_world = Eigen::Vector3d::Zero();                 // body origin in the world, metres
  Eigen::Quaterniond q_world_body = Eigen::Quaterniond::Identity();  // unit; meaningless if !has_rotation
  // False for a line whose quaternion is exactly "0 0 0 0" (translation-only ground truth such as the M2DGR
  // Leica tracker): the rotation is unknown. Such a pose is never normalized and writes back as 0 0 0 0.
  bool has_rotation = true;
};

struct TumReadOptions {
  // A non-zero quaternion whose norm differs from 1 by more than this is an error (text files round to ~7
  // digits, so small deviations are normalized away).
  double quaternion_norm_tolerance = 1e-3;
  bool require_increasing_time = true;  // timestamps strictly increasing, else IoError
};

// Reads a TUM file. Blank lines and '#' comments are skipped. IoError (file, line, problem) on a missing
// file, a field count other than 8, a non-finite or unparsable value, a bad quaternion norm, or a
// timestamp not greater than the previous one.
std::vector<TumPose> read_tum(const std::filesystem::path& path, const TumReadOptions& options = {});

// T_world_body at time t of a trajectory sorted by time (4x4). A pose within snap_s of t is used as it is;
// otherwise the two poses around t are interpolated (translation linearly, rotation by slerp). nullopt
// before the first or after the last pose, or where a pose needed has an unknown rotation.
std::optional<Eigen::Matrix4d> tum_pose_at(const std::vector<TumPose>& poses, double t, double snap_s = 0);

// Writes atomically with round-trip exact numbers; unknown rotations as "0 0 0 0".
void write_tum(const std::filesystem::path& path, const std::vector<TumPose>& poses);

}  // namespace litgs::io
