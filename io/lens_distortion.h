// The thermal camera's lens model on normalized image coordinates (x = X/Z, y = Y/Z): OpenCV's radtan
// (k1 k2 p1 p2 [k3]) for CameraModel::kPinhole and the equidistant fisheye (k1 k2 k3 k4) for kEquidistant.
#pragma once

#include <Eigen/Core>
#include <optional>

#include "io/scene_types.h"

namespace litgs::io {

// Undistorted normalized (x, y) -> distorted normalized, as OpenCV's projectPoints / fisheye::projectPoints.
Eigen::Vector2d distort_normalized(const CameraIntrinsics& k, const Eigen::Vector2d& undistorted);

// The inverse: the undistorted normalized point whose distortion is `distorted`, by Newton's method to
// 1e-12, or nullopt where it does not converge (beyond the lens model's monotonic range). No distortion
// returns the point as is.
std::optional<Eigen::Vector2d> undistort_normalized(const CameraIntrinsics& k,
                                                    const Eigen::Vector2d& distorted);

// The viewing ray through pixel (u, v) (pixel centres at integers) in the camera frame, z = 1 (not unit
// length); nullopt where undistort_normalized has no answer.
std::optional<Eigen::Vector3d> pixel_ray(const CameraIntrinsics& k, double u, double v);

}  // namespace litgs::io
