#include "host/synth/imu_sim.h"

#include <cmath>
#include <stdexcept>

namespace litgs::host::synth {

std::string ImuOptions::check() const {
  if (!(rate_hz > 0 && rate_hz <= 10000)) return "rate_hz: must be in (0, 10000]";
  if (!(gyro_noise_rad_s >= 0)) return "gyro_noise_rad_s: must be >= 0";
  if (!(accel_noise_m_s2 >= 0)) return "accel_noise_m_s2: must be >= 0";
  if (!(gyro_bias_rad_s >= 0)) return "gyro_bias_rad_s: must be >= 0";
  if (!(accel_bias_m_s2 >= 0)) return "accel_bias_m_s2: must be >= 0";
  if (!(gravity_m_s2 >= 0)) return "gravity_m_s2: must be >= 0";
  return "";
}

std::vector<io::ImuSample> simulate_imu(const Trajectory& trajectory, double t_origin_s, double t_begin_s,
                                        double t_end_s, const ImuOptions& o, Rng& rng, ImuBias& bias) {
  const std::string problem = o.check();
  if (!problem.empty()) throw std::invalid_argument("ImuOptions." + problem);
  bias.gyro_rad_s = o.gyro_bias_rad_s * Eigen::Vector3d(rng.normal(), rng.normal(), rng.normal());
  bias.accel_m_s2 = o.accel_bias_m_s2 * Eigen::Vector3d(rng.normal(), rng.normal(), rng.normal());
  const Eigen::Vector3d g_world(0, 0, -o.gravity_m_s2);
  std::vector<io::ImuSample> out;
  // Integer sample indices: times never accumulate rounding and stay strictly increasing.
  const auto k0 = static_cast<int64_t>(std::ceil(t_begin_s * o.rate_hz));
  const auto k1 = static_cast<int64_t>(std::floor(t_end_s * o.rate_hz));
  for (int64_t k = k0; k <= k1; ++k) {
    const double t = static_cast<double>(k) / o.rate_hz;
    const TrajectoryState s = trajectory.at(t);
    io::ImuSample sample;
    sample.t_s = t_origin_s + t;
    sample.gyro_rad_s = s.omega_body_rad_s + bias.gyro_rad_s +
                        o.gyro_noise_rad_s * Eigen::Vector3d(rng.normal(), rng.normal(), rng.normal());
    sample.accel_m_s2 = s.R_world_body.transpose() * (s.a_world_m_s2 - g_world) + bias.accel_m_s2 +
                        o.accel_noise_m_s2 * Eigen::Vector3d(rng.normal(), rng.normal(), rng.normal());
    out.push_back(sample);
  }
  return out;
}

}  // namespace litgs::host::synth
