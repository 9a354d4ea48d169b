// A small programmatic scene for the refinement tests: a world of rectangles, a camera path with its true
// poses and drifting priors, synthetic tracks, a LiDAR plane map sampled from the world, and anchors.
#pragma once

#include <functional>
#include <vector>

#include "host/refine/refine.h"
#include "host/refine/synthetic_tracks.h"
#include "host/synth/geometry.h"
#include "host/train/lidar_planes.h"

namespace litgs::host::refine::testing {

struct TestSceneOptions {
  size_t frames = 40;
  double speed_m_per_frame = 0.15;  // along +x; 0 with rotate_rad_per_frame: pure rotation
  double rotate_rad_per_frame = 0;  // yaw per frame
  double drift_per_m = 0.01;        // prior position drift: drift_per_m * travelled^2 / 1 m, along drift_dir
  double initial_offset_m = 0;      // a constant offset of every prior position along drift_dir
  Eigen::Vector3d drift_dir = Eigen::Vector3d(0.3, 0.8, 0.5).normalized();
  double rotation_drift_per_m = 0.002;  // rad per metre, about z
  double jitter_m = 0.002;
  double weave_m = 1.0;       // sideways (toward the facade) sine of one period over the path
  bool single_plane = false;  // only the facade wall
  size_t anchors = 60;
  double anchor_sigma_m = 0.02;
  double anchor_min_sigma_m = -1;  // > 0: one axis of every anchor covariance has this sigma (near singular)
  SyntheticTrackOptions tracks;
  uint64_t seed = 3;
};

struct TestScene {
  synth::World world;
  PinholeCamera camera;
  std::vector<CameraPose> truth, priors;
  PlanarMap map;
  std::vector<AnchorPoint> anchors;
  std::vector<Eigen::Vector3d> anchors_true;
  RefineInput input;  // points, priors, anchors, map (pointing into this object: do not copy)
};

// Fills `scene` (not copyable: input.map points at scene.map).
void make_test_scene(TestScene& scene, const TestSceneOptions& options);

// SE(3)-aligned ATE of poses against the truth.
double ate(const std::vector<CameraPose>& poses, const std::vector<CameraPose>& truth);

}  // namespace litgs::host::refine::testing
