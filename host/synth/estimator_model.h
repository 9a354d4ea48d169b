// The upstream estimator's view, as FAST-LIVO2 would hand it on: camera poses that drift with the distance
// travelled plus per-frame jitter, and visual map points (anchors) whose error is drawn from the very
// covariance they report.
#pragma once

#include <Eigen/Core>
#include <Eigen/Geometry>
#include <string>
#include <vector>

#include "host/synth/geometry.h"
#include "host/synth/rng.h"
#include "io/scene_types.h"
#include "io/tum.h"

namespace litgs::host::synth {

struct EstimatorNoiseOptions {
  double drift_m_per_m = 0.01;         // translation drift per metre travelled (one fixed direction)
  double drift_rad_per_m = 0.0003;     // rotation drift per metre travelled (one fixed axis)
  double pose_noise_m = 0.005;         // per-frame position jitter (standard deviation per axis)
  double pose_noise_rad = 0.0003;      // per-frame rotation jitter (standard deviation per axis)
  int anchors_per_frame = 20;          // visual map points picked per frame (fewer on textureless views)
  double anchor_pixel_sigma_px = 0.5;  // lateral standard deviation, as a pixel error at the anchor's depth
  double anchor_depth_sigma_m = 0.02;  // standard deviation along the viewing ray
  double anchor_min_gradient_raw = 6;  // only pixels with at least this radiance gradient (counts/pixel)
  int anchor_border_px = 8;            // anchors are picked at least this far from the image border

  std::string check() const;  // empty if valid, else the first bad field and why
};

// Estimated poses: drift = distance_m[i] * (rate * a fixed random direction / axis), applied on the world
// side, then jitter. `distance_m[i]` is the distance travelled at pose i.
std::vector<io::TumPose> drift_poses(const std::vector<io::TumPose>& truth,
                                     const std::vector<double>& distance_m,
                                     const EstimatorNoiseOptions& options, Rng& rng);

// Anchors picked in one frame: pixels with a radiance gradient, ray cast with the true pose. `truth` gets
// the exact points (index for index with the returned anchors).
std::vector<io::Anchor> pick_anchors(const World& world, const io::CameraIntrinsics& K,
                                     const Eigen::Isometry3d& T_world_cam,
                                     const EstimatorNoiseOptions& options, Rng& rng,
                                     std::vector<Eigen::Vector3d>& truth);

}  // namespace litgs::host::synth
