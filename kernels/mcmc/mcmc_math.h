// The MCMC strategy's math, written once in the common subset of GLSL and C++: the kernels compile it in
// float32, the CPU reference (mcmc_reference.cc) in double. Relocation (3DGS-MCMC, eq. 9), the position
// noise gate, and the normal samples of the noise. GLSL includers include splat/splat_math.h,
// densify/densify_shared.h and densify/densify_math.h first.
#ifndef LITGS_KERNELS_MCMC_MATH_H
#define LITGS_KERNELS_MCMC_MATH_H

#ifdef __cplusplus
#include "kernels/densify/densify_math.h"
#include "kernels/splat/splat_math.h"

namespace litgs::kernels::mcmc_math {
using namespace splat_math;
using densify_math::pcg_hash;
using densify_math::split_uniform;
using uint = uint32_t;
#define MM_FN inline
#else
#define MM_FN
#endif

// log(1 - e) and 1 - exp(y) (y <= 0) without the cancellation of the direct forms near 0 (GLSL has no
// log1p/expm1): three series terms below 1e-3 leave a relative error under 1e-12.
MM_FN real log_one_minus(real e) {
  return e < real(1e-3) ? -e * (real(1.0) + e * (real(0.5) + e / real(3.0))) : log(real(1.0) - e);
}
MM_FN real one_minus_exp(real y) {
  return y > real(-1e-3) ? -y * (real(1.0) + y * (real(0.5) + y / real(6.0))) : real(1.0) - exp(y);
}

// The opacity each of n copies gets so that the n stacked copies are as opaque as the original:
// 1 - (1 - o)^(1/n).
MM_FN real relocated_opacity(real o, uint n) {
  return one_minus_exp(log_one_minus(o) / real(n));
}

// 3DGS-MCMC's normalizer sum_{i=1..n} sum_{k=0..i-1} C(i-1,k) (-1)^k x^(k+1) / sqrt(k+1). That alternating
// sum cancels (at n = 51 its terms grow to ~1e5 for a result of about 2: float keeps four digits), so it is
// evaluated in its equivalent positive form (1/sqrt(k+1) = pi^-1/2 int t^-1/2 e^-(k+1)t dt, then the binomial
// and geometric sums close, and t = s^2):
//     (2 / sqrt(pi)) int_0^inf [1 - (1 - x e^(-s^2))^n] ds,
// whose integrand is smooth, in [0, 1] and even in s: the trapezoid rule with step h is spectrally accurate
// (n = 1 gives x exactly). `steps` points past s = 0 cover [0, steps h]; beyond s = 6 the integrand is below
// n e^-36.
MM_FN real stacked_opacity_integral(real x, uint n, real h, uint steps) {
  real sum = real(0.5) * one_minus_exp(real(n) * log_one_minus(x));
  for (uint j = 1u; j <= steps; ++j) {
    const real s = real(j) * h;
    sum += one_minus_exp(real(n) * log_one_minus(x * exp(-s * s)));
  }
  return real(2.0) / sqrt(real(3.14159265358979323846)) * h * sum;
}

// The change of every log-scale of a Gaussian of opacity o relocated into n copies of opacity o_new:
// log(o / stacked_opacity_integral(o_new, n)), so that the copies' summed opacity profile keeps the
// original's peak (3DGS-MCMC eq. 9).
MM_FN real relocation_log_scale_delta(real o, real o_new, uint n) {
  return log(o / stacked_opacity_integral(o_new, n, real(0.1), 60u));
}

// 3DGS-MCMC's noise gate: a sigmoid of (1 - opacity) with slope 100 centred at 0.995, so that only nearly
// transparent Gaussians move (op_sigmoid in the reference implementation).
MM_FN real noise_gate(real opacity_logit) {
  const real one_minus_o = real(1.0) / (real(1.0) + exp(opacity_logit));
  return real(1.0) / (real(1.0) + exp(real(-100.0) * (one_minus_o - real(0.995))));
}

// Three standard normal samples for Gaussian `index` at `step` (Box-Muller on the counter-based hash).
MM_FN vec3 noise_normals(uint seed, uint step, uint index) {
  const real u1 = real(split_uniform(seed, step, index, 7u, 0u, 0u));
  const real u2 = real(split_uniform(seed, step, index, 7u, 0u, 1u));
  const real u3 = real(split_uniform(seed, step, index, 7u, 1u, 0u));
  const real u4 = real(split_uniform(seed, step, index, 7u, 1u, 1u));
  const real two_pi = real(6.28318530717958647692);
  const real r1 = sqrt(real(-2.0) * log(u1)), r2 = sqrt(real(-2.0) * log(u3));
  return vec3(r1 * cos(two_pi * u2), r1 * sin(two_pi * u2), r2 * cos(two_pi * u4));
}

#ifdef __cplusplus
}  // namespace litgs::kernels::mcmc_math
#endif
#undef MM_FN
#endif
