#include "kernels/level/level_reference.h"

#include <algorithm>
#include <cmath>

namespace litgs::kernels {

double level_r2_reference(const LevelGeometry& g, uint64_t e) {
  const uint64_t pixel = e % (uint64_t{g.width} * g.height);
  const double dx = static_cast<double>(pixel % g.width) + 0.5 - g.cx;
  const double dy = static_cast<double>(pixel / g.width) + 0.5 - g.cy;
  return (dx * dx + dy * dy) / (0.25 * g.width * g.width + 0.25 * g.height * g.height);
}

namespace {
double vignetting_at(const LevelGeometry& g, uint64_t e, const LevelValues& v, bool vignetting) {
  if (!vignetting) return 1.0;
  const double r2 = level_r2_reference(g, e);
  return 1.0 + v.k1 * r2 + v.k2 * r2 * r2;
}
}  // namespace

std::vector<double> level_apply_reference(const std::vector<float>& image, const LevelGeometry& g,
                                          const LevelValues& v, bool vignetting) {
  std::vector<double> out(image.size());
  const double gain = std::exp(v.log_gain);
  for (size_t e = 0; e < image.size(); ++e)
    out[e] = gain * vignetting_at(g, e, v, vignetting) * image[e] + v.offset;
  return out;
}

LevelBackwardReference level_backward_reference(const std::vector<float>& image,
                                                const std::vector<float>& grad_leveled,
                                                const LevelGeometry& g, const LevelValues& v,
                                                bool vignetting) {
  LevelBackwardReference r;
  r.grad_image.resize(image.size());
  const double gain = std::exp(v.log_gain);
  for (size_t e = 0; e < image.size(); ++e) {
    const double G = grad_leveled[e];
    const double vig = vignetting_at(g, e, v, vignetting);
    const double r2 = vignetting ? level_r2_reference(g, e) : 0.0;
    r.grad_image[e] = G * gain * vig;
    r.grad[0] += G * gain * vig * image[e];
    r.grad[1] += G;
    r.grad[2] += G * gain * image[e] * r2;
    r.grad[3] += G * gain * image[e] * r2 * r2;
  }
  return r;
}

double level_regularizer_reference(const std::vector<double>& state, uint32_t frames, bool vignetting,
                                   double lambda_identity, double lambda_smooth,
                                   const std::vector<std::array<uint32_t, 2>>& pairs) {
  double r = 0;
  for (uint32_t f = 0; f < frames; ++f) {
    const double lg = state[size_t{f} * LEVEL_STRIDE], o = state[size_t{f} * LEVEL_STRIDE + 1];
    r += lambda_identity * (lg * lg + o * o);
  }
  if (vignetting) {
    const double k1 = state[size_t{frames} * LEVEL_STRIDE], k2 = state[size_t{frames} * LEVEL_STRIDE + 1];
    r += lambda_identity * (k1 * k1 + k2 * k2);
  }
  for (const auto& [a, b] : pairs)
    for (int i = 0; i < 2; ++i) {
      const double d = state[size_t{a} * LEVEL_STRIDE + i] - state[size_t{b} * LEVEL_STRIDE + i];
      r += lambda_smooth * d * d;
    }
  return r;
}

namespace {
// Adam on the two parameters of `row` (clamped to +-limit where limit > 0); false: not finite, unchanged.
bool adam2(std::vector<double>& s, size_t row, const std::array<double, 2>& g,
           const std::array<double, 2>& lr, const std::array<double, 2>& limit, const LevelStep& p) {
  const double steps = s[row + LEVEL_STEPS] + 1;
  const double bc1 = 1 - std::pow(double{p.beta1}, steps), bc2 = 1 - std::pow(double{p.beta2}, steps);
  std::array<double, 6> next{};
  for (int i = 0; i < 2; ++i) {
    const double m = p.beta1 * s[row + 2 + i] + (1 - double{p.beta1}) * g[i];
    const double v = p.beta2 * s[row + 4 + i] + (1 - double{p.beta2}) * g[i] * g[i];
    double x = s[row + i] - lr[i] / bc1 * (m / (std::sqrt(v) / std::sqrt(bc2) + p.eps));
    if (!std::isfinite(g[i]) || !std::isfinite(x)) return false;
    if (limit[i] > 0) x = std::clamp(x, -limit[i], limit[i]);
    next[i] = x, next[2 + i] = m, next[4 + i] = v;
  }
  std::copy(next.begin(), next.end(), s.begin() + static_cast<std::ptrdiff_t>(row));
  s[row + LEVEL_STEPS] = steps;
  return true;
}
}  // namespace

std::array<double, 4> level_step_gradient_reference(const std::vector<double>& s, uint32_t frames,
                                                    const std::array<double, 4>& grad, const LevelStep& p) {
  std::array<double, 4> g = grad;
  const size_t row = size_t{p.frame} * LEVEL_STRIDE, shared_row = size_t{frames} * LEVEL_STRIDE;
  for (int i = 0; i < 2; ++i) {
    g[i] += 2 * double{p.lambda_identity} * s[row + i];
    for (int n : {p.prev, p.next})
      if (n >= 0) g[i] += 2 * double{p.lambda_smooth} * (s[row + i] - s[size_t(n) * LEVEL_STRIDE + i]);
    g[2 + i] += 2 * double{p.lambda_identity} * s[shared_row + i];
  }
  return g;
}

void level_step_reference(std::vector<double>& s, uint32_t frames, bool vignetting,
                          const std::array<double, 4>& grad, const LevelStep& p) {
  const size_t shared_row = size_t{frames} * LEVEL_STRIDE;
  const std::array<double, 4> g = level_step_gradient_reference(s, frames, grad, p);
  double skipped = 0;
  if (!adam2(s, size_t{p.frame} * LEVEL_STRIDE, {g[0], g[1]}, {p.lr_log_gain, p.lr_offset},
             {LEVEL_LOG_GAIN_LIMIT, 0.0}, p))
    skipped += 1;
  if (vignetting && !adam2(s, shared_row, {g[2], g[3]}, {p.lr_vignetting, p.lr_vignetting},
                           {LEVEL_VIGNETTING_LIMIT, LEVEL_VIGNETTING_LIMIT}, p))
    skipped += 1;
  s[shared_row + LEVEL_SKIPS] += skipped;
  if (!p.center) return;
  // The mean's gauge: trained frames' log-gains clamped, then both means subtracted.
  double lg = 0, o = 0, n = 0;
  for (size_t f = 0; f < frames; ++f) {
    const size_t r = f * LEVEL_STRIDE;
    if (s[r + LEVEL_TRAINED] == 0) continue;
    s[r] = std::clamp(s[r], -LEVEL_LOG_GAIN_LIMIT, LEVEL_LOG_GAIN_LIMIT);
    lg += s[r], o += s[r + 1], n += 1;
  }
  if (n == 0) return;
  for (size_t f = 0; f < frames; ++f) {
    const size_t r = f * LEVEL_STRIDE;
    if (s[r + LEVEL_TRAINED] == 0) continue;
    s[r] -= lg / n;
    s[r + 1] -= o / n;
  }
}

}  // namespace litgs::kernels
