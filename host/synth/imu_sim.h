// IMU simulation from the trajectory's closed-form derivatives: gyro = omega_body + bias + noise,
// accel = R_world_body^T (a_world - g_world) + bias + noise (the specific force: at rest it reads +g up).
#pragma once

#include <Eigen/Core>
#include <string>
#include <vector>

#include "host/synth/rng.h"
#include "host/synth/trajectory.h"
#include "io/scene_types.h"

namespace litgs::host::synth {

struct ImuOptions {
  double rate_hz = 200;             // sample rate
  double gyro_noise_rad_s = 0.003;  // white noise per sample (standard deviation)
  double accel_noise_m_s2 = 0.03;   // white noise per sample
  double gyro_bias_rad_s = 0.002;   // constant bias drawn per axis with this standard deviation
  double accel_bias_m_s2 = 0.03;    // constant bias drawn per axis with this standard deviation
  double gravity_m_s2 = 9.81;       // magnitude; gravity points to world -z

  std::string check() const;  // empty if valid, else the first bad field and why
};

struct ImuBias {
  Eigen::Vector3d gyro_rad_s = Eigen::Vector3d::Zero();
  Eigen::Vector3d accel_m_s2 = Eigen::Vector3d::Zero();
};

// Samples at t_origin_s + trajectory time, for trajectory times k / rate in [t_begin_s, t_end_s]. The biases
// drawn are returned in `bias` (ground truth).
std::vector<io::ImuSample> simulate_imu(const Trajectory& trajectory, double t_origin_s, double t_begin_s,
                                        double t_end_s, const ImuOptions& options, Rng& rng, ImuBias& bias);

}  // namespace litgs::host::synth
