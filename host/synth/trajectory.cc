#include "host/synth/trajectory.h"

#include <cmath>
#include <numbers>
#include <stdexcept>

namespace litgs::host::synth {
namespace {

constexpr double kTwoPi = 2 * std::numbers::pi;

Eigen::Matrix3d rot_x(double a) {
  return Eigen::AngleAxisd(a, Eigen::Vector3d::UnitX()).toRotationMatrix();
}
Eigen::Matrix3d rot_y(double a) {
  return Eigen::AngleAxisd(a, Eigen::Vector3d::UnitY()).toRotationMatrix();
}
Eigen::Matrix3d rot_z(double a) {
  return Eigen::AngleAxisd(a, Eigen::Vector3d::UnitZ()).toRotationMatrix();
}

// A sinusoid a sin(w x + phase) and its first two derivatives in x.
struct Sine {
  double f, d1, d2;
};
Sine sine(double a, double w, double x, double phase = 0) {
  const double s = std::sin(w * x + phase), c = std::cos(w * x + phase);
  return {a * s, a * w * c, -a * w * w * s};
}

}  // namespace

std::string TrajectoryOptions::check() const {
  if (!start_m.allFinite()) return "start_m: not finite";
  if (!(speed_mean_m_s > 0)) return "speed_mean_m_s: must be > 0";
  if (!(speed_amplitude_m_s >= 0 && speed_amplitude_m_s < speed_mean_m_s))
    return "speed_amplitude_m_s: must be in [0, speed_mean_m_s) so the rig never stops or reverses";
  for (const auto& [name, value] : {std::pair{"speed_period_s", speed_period_s},
                                    {"weave_wavelength_m", weave_wavelength_m},
                                    {"bob_wavelength_m", bob_wavelength_m},
                                    {"yaw_period_s", yaw_period_s},
                                    {"pitch_period_s", pitch_period_s},
                                    {"roll_period_s", roll_period_s}})
    if (!(value > 0)) return std::string(name) + ": must be > 0";
  if (std::abs(pitch_amplitude_rad) >= 1.2) return "pitch_amplitude_rad: must be below 1.2 (gimbal lock)";
  return "";
}

Eigen::Isometry3d TrajectoryState::T_world_body() const {
  Eigen::Isometry3d T = Eigen::Isometry3d::Identity();
  T.linear() = R_world_body;
  T.translation() = p_world_m;
  return T;
}

Trajectory::Trajectory(const TrajectoryOptions& options) : o_(options) {
  const std::string problem = o_.check();
  if (!problem.empty()) throw std::invalid_argument("TrajectoryOptions." + problem);
}

TrajectoryState Trajectory::at(double t) const {
  // Arc length s(t) of the base line and its derivatives.
  const double ws = kTwoPi / o_.speed_period_s;
  const double s = o_.speed_mean_m_s * t + o_.speed_amplitude_m_s / ws * (1 - std::cos(ws * t));
  const double sd = o_.speed_mean_m_s + o_.speed_amplitude_m_s * std::sin(ws * t);
  const double sdd = o_.speed_amplitude_m_s * ws * std::cos(ws * t);

  // The path in its local frame (x along the line) as a function of s.
  const Sine y = sine(o_.weave_amplitude_m, kTwoPi / o_.weave_wavelength_m, s);
  const Sine z = sine(o_.bob_amplitude_m, kTwoPi / o_.bob_wavelength_m, s);
  const Eigen::Vector3d P(s, y.f, z.f), P1(1, y.d1, z.d1), P2(0, y.d2, z.d2);
  const Eigen::Matrix3d R_heading = rot_z(o_.heading_rad);

  TrajectoryState st;
  st.distance_m = s;
  st.p_world_m = o_.start_m + R_heading * P;
  st.v_world_m_s = R_heading * P1 * sd;
  st.a_world_m_s2 = R_heading * (P2 * sd * sd + P1 * sdd);

  // Z-Y-X Euler angles: yaw follows the path's tangent plus an oscillation.
  const Sine yaw_osc = sine(o_.yaw_amplitude_rad, kTwoPi / o_.yaw_period_s, t);
  const Sine pitch = sine(o_.pitch_amplitude_rad, kTwoPi / o_.pitch_period_s, t, 0.7);
  const Sine roll = sine(o_.roll_amplitude_rad, kTwoPi / o_.roll_period_s, t, 1.9);
  const double yaw = o_.heading_rad + std::atan(y.d1) + yaw_osc.f;
  const double yaw_dot = y.d2 * sd / (1 + y.d1 * y.d1) + yaw_osc.d1;
  const Eigen::Matrix3d Rx = rot_x(roll.f), Ry = rot_y(pitch.f);
  st.R_world_body = rot_z(yaw) * Ry * Rx;
  st.omega_body_rad_s = Eigen::Vector3d(roll.d1, 0, 0) + Rx.transpose() * Eigen::Vector3d(0, pitch.d1, 0) +
                        (Ry * Rx).transpose() * Eigen::Vector3d(0, 0, yaw_dot);
  return st;
}

}  // namespace litgs::host::synth
