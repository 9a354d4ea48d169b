#include "host/synth/thermal_texture.h"

#include <algorithm>
#include <cmath>
#include <limits>

#include "host/synth/rng.h"

namespace litgs::host::synth {
namespace {

double smooth(double t) {
  return t * t * (3 - 2 * t);
}

// Value noise in [-1, 1] on a unit lattice: smooth, deterministic, a pure function of (x, y, seed).
double value_noise(double x, double y, uint64_t seed) {
  const double fx = std::floor(x), fy = std::floor(y);
  const auto ix = static_cast<int64_t>(fx), iy = static_cast<int64_t>(fy);
  auto corner = [&](int64_t a, int64_t b) {
    return 2 * hash_uniform(
                   hash_combine(hash_combine(seed, static_cast<uint64_t>(a)), static_cast<uint64_t>(b))) -
           1;
  };
  const double tx = smooth(x - fx), ty = smooth(y - fy);
  const double c00 = corner(ix, iy), c10 = corner(ix + 1, iy), c01 = corner(ix, iy + 1),
               c11 = corner(ix + 1, iy + 1);
  return (c00 * (1 - tx) + c10 * tx) * (1 - ty) + (c01 * (1 - tx) + c11 * tx) * ty;
}

// The integral over [0, x] of a pulse train of period p with pulses [0, w): lets a joint be box-filtered.
double pulse_integral(double x, double p, double w) {
  const double n = std::floor(x / p);
  return n * w + std::min(x - n * p, w);
}

// Fraction of [x - h/2, x + h/2] covered by the joints (width w, period p, centred on the cell borders).
double joint_coverage(double x, double p, double w, double h) {
  const double shifted = x + w / 2;  // joints straddle the cell borders
  if (h <= 1e-9) {
    const double r = shifted - std::floor(shifted / p) * p;
    return r < w ? 1.0 : 0.0;
  }
  return (pulse_integral(shifted + h / 2, p, w) - pulse_integral(shifted - h / 2, p, w)) / h;
}

// Multi-scale value noise in about [-1, 1] * sum of amplitudes; octaves below twice the footprint fade.
double weathering(const ThermalTexture& t, double u, double v, double footprint_m) {
  double sum = 0, amplitude = 1, scale = t.detail_scale_m;
  for (int k = 0; k < t.detail_octaves; ++k, amplitude *= t.detail_gain, scale /= 2) {
    const double resolved = std::clamp(scale / (2 * footprint_m + 1e-12) - 1, 0.0, 1.0);
    if (resolved <= 0) break;
    sum += resolved * amplitude * value_noise(u / scale, v / scale, t.seed + 0x77 * (k + 1));
  }
  return sum;
}

double halo_heat(const WarmHalo& h, double u, double v) {
  const double du = std::max({h.u0_m - u, 0.0, u - h.u1_m});
  const double below = std::max(h.v0_m - v, 0.0), above = std::max(v - h.v1_m, 0.0) / 2;
  const double dv = std::max(below, above);
  return h.raw * std::exp(-(du * du + dv * dv) / (2 * h.radius_m * h.radius_m));
}

}  // namespace

namespace {

// The share of a pixel footprint around (u, v) inside the nearest circle of the grid: a linear ramp across
// the edge over the footprint, so that the rendered circles are anti-aliased and their centres unbiased.
double circle_coverage(const CircleGridPattern& g, double u, double v, double footprint_m) {
  const double x = (u - g.origin_u_m) / g.spacing_m, y = (v - g.origin_v_m) / g.spacing_m;
  double nearest = std::numeric_limits<double>::infinity();
  const int row = static_cast<int>(std::lround(y));
  for (int i = std::max(0, row - 1); i <= std::min(g.rows - 1, row + 1); ++i) {
    const int j = std::clamp(static_cast<int>(std::lround((x - i % 2) / 2)), 0, g.cols - 1);
    nearest = std::min(nearest, std::hypot(x - (2 * j + i % 2), y - i) * g.spacing_m);
  }
  const double width = std::max(footprint_m, 1e-9);
  return std::clamp((g.radius_m - nearest) / width + 0.5, 0.0, 1.0);
}

}  // namespace

ThermalTexture calibration_room_wall() {
  ThermalTexture wall;
  wall.base_raw = 3300;
  wall.noise_raw = 20;
  wall.noise_scale_m = 1;
  return wall;
}

double thermal_radiance(const ThermalTexture& t, double u, double v, double footprint_m) {
  double raw = t.base_raw + t.gradient_v_raw_per_m * v;
  raw += t.noise_raw * value_noise(u / t.noise_scale_m, v / t.noise_scale_m, t.seed);
  if (t.pattern == ThermalPattern::kCircleGrid) {
    raw += t.circles.raw * circle_coverage(t.circles, u, v, footprint_m);
  } else if (t.pattern != ThermalPattern::kUniform) {
    const double row = std::floor(v / t.cell_v_m);
    // Running bond: every other brick row is shifted by half a brick.
    const double shift =
        (t.pattern == ThermalPattern::kBrick && std::fmod(std::abs(row), 2.0) == 1.0) ? t.cell_u_m / 2 : 0.0;
    const double col = std::floor((u + shift) / t.cell_u_m);
    const uint64_t cell = hash_combine(hash_combine(t.seed ^ 0x5eedull, static_cast<uint64_t>(row)),
                                       static_cast<uint64_t>(col));
    raw += t.cell_jitter_raw * (2 * hash_uniform(cell) - 1);
    const double cu = joint_coverage(u + shift, t.cell_u_m, t.joint_m, footprint_m);
    const double cv = joint_coverage(v, t.cell_v_m, t.joint_m, footprint_m);
    raw += t.joint_raw * (cu + cv - cu * cv);
  }
  if (t.detail_octaves > 0) raw += t.detail_raw * weathering(t, u, v, footprint_m);
  if (t.streak_raw != 0) {
    // Narrow along u (0.12 m), long along v (3 m), only the positive lobes: stains run down from sills.
    const double s = value_noise(u / 0.12, v / 3.0, t.seed ^ 0x57ea4ull);
    raw -= t.streak_raw * std::max(0.0, s);
  }
  for (const WarmHalo& h : t.halos) raw += halo_heat(h, u, v);
  if (t.spot_raw != 0) {
    const double du = u - t.spot_u_m, dv = v - t.spot_v_m;
    raw += t.spot_raw * std::exp(-(du * du + dv * dv) / (2 * t.spot_radius_m * t.spot_radius_m));
  }
  return raw;
}

}  // namespace litgs::host::synth
