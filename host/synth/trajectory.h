// A smooth rig trajectory with closed-form derivatives: the IMU is simulated from them, never from finite
// differences. The path weaves sideways and bobs along a straight line; the speed along it alternates
// between slow and fast segments; the body yaws, pitches and rolls as a hand-held or vehicle rig does.
//
// Body frame = IMU frame: x forward, y left, z up. World: z up.
#pragma once

#include <Eigen/Core>
#include <Eigen/Geometry>
#include <string>

namespace litgs::host::synth {

struct TrajectoryOptions {
  Eigen::Vector3d start_m = Eigen::Vector3d(0, 0, 1.5);  // body origin at t = 0 (world)
  double heading_rad = 0;            // direction of the path in the horizontal plane (0: world +x)
  double speed_mean_m_s = 1.2;       // mean speed along the path
  double speed_amplitude_m_s = 0.6;  // speed = mean + amplitude sin(2 pi t / period): slow and fast parts
  double speed_period_s = 4;         // period of the slow/fast alternation
  double weave_amplitude_m = 0.3;    // sideways sinusoid along the path
  double weave_wavelength_m = 8;
  double bob_amplitude_m = 0.05;  // vertical sinusoid along the path
  double bob_wavelength_m = 1.5;
  double yaw_amplitude_rad = 0.08;  // yaw oscillation on top of following the path's tangent
  double yaw_period_s = 3.1;
  double pitch_amplitude_rad = 0.04;  // pitch oscillation
  double pitch_period_s = 2.3;
  double roll_amplitude_rad = 0.03;  // roll oscillation
  double roll_period_s = 1.7;

  // Empty if valid, else the first bad field and why.
  std::string check() const;
};

// The state at one time, all in closed form.
struct TrajectoryState {
  Eigen::Matrix3d R_world_body = Eigen::Matrix3d::Identity();
  Eigen::Vector3d p_world_m = Eigen::Vector3d::Zero();         // body origin
  Eigen::Vector3d v_world_m_s = Eigen::Vector3d::Zero();       // its velocity
  Eigen::Vector3d a_world_m_s2 = Eigen::Vector3d::Zero();      // its acceleration (no gravity)
  Eigen::Vector3d omega_body_rad_s = Eigen::Vector3d::Zero();  // angular velocity in the body frame
  double distance_m = 0;                                       // arc length travelled along the base path

  Eigen::Isometry3d T_world_body() const;
};

class Trajectory {
 public:
  explicit Trajectory(const TrajectoryOptions& options);  // throws std::invalid_argument (check())
  // t_s is relative to the trajectory's start.
  TrajectoryState at(double t_s) const;
  const TrajectoryOptions& options() const { return o_; }

 private:
  TrajectoryOptions o_;
};

}  // namespace litgs::host::synth
