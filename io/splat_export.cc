#include "io/splat_export.h"

#include <algorithm>
#include <cmath>
#include <cstring>
#include <numeric>
#include <stdexcept>

#include "io/atomic_file.h"

namespace litgs::io {
namespace {

constexpr double kShC0 = 0.28209479177387814;  // the degree-0 SH basis: colour = 0.5 + C0 * f_dc

uint8_t unit_to_byte(double v) {
  return static_cast<uint8_t>(std::lround(std::clamp(std::isfinite(v) ? v : 0.0, 0.0, 1.0) * 255.0));
}

}  // namespace

std::vector<uint8_t> encode_splat(const kernels::GaussianModel& m, const SplatColouring& colouring) {
  m.check();
  if (colouring.palette && m.channels != 1)
    throw std::invalid_argument("a palette needs a one-channel model; this one has " +
                                std::to_string(m.channels) + " channels");
  if (colouring.palette &&
      !(colouring.hi > colouring.lo && std::isfinite(colouring.lo) && std::isfinite(colouring.hi)))
    throw std::invalid_argument("the palette range needs finite LO < HI");
  const size_t n = m.size(), k = m.sh_coeffs(), c = m.channels;
  auto opacity = [&](size_t i) { return 1.0 / (1.0 + std::exp(-double(m.opacity_logits[i]))); };
  std::vector<double> importance(n);
  for (size_t i = 0; i < n; ++i)
    importance[i] =
        std::exp(double(m.log_scales[3 * i]) + m.log_scales[3 * i + 1] + m.log_scales[3 * i + 2]) *
        opacity(i);
  std::vector<size_t> order(n);
  std::iota(order.begin(), order.end(), size_t{0});
  std::stable_sort(order.begin(), order.end(),
                   [&](size_t a, size_t b) { return importance[a] > importance[b]; });

  std::vector<uint8_t> out(n * 32);
  for (size_t row = 0; row < n; ++row) {
    const size_t i = order[row];
    uint8_t* p = out.data() + row * 32;
    float f[6];
    for (int a = 0; a < 3; ++a) f[a] = m.means[3 * i + a];
    for (int a = 0; a < 3; ++a) f[3 + a] = static_cast<float>(std::exp(double(m.log_scales[3 * i + a])));
    std::memcpy(p, f, sizeof f);  // little-endian host (x86-64, arm64)
    const float* dc = &m.sh[i * k * c];
    if (c == 1) {
      const double v = 0.5 + kShC0 * dc[0];
      if (colouring.palette) {
        const Rgb rgb = palette_table(*colouring.palette)[palette_index(v, colouring.lo, colouring.hi)];
        std::copy(rgb.begin(), rgb.end(), p + 24);
      } else {
        p[24] = p[25] = p[26] = unit_to_byte(v);
      }
    } else {
      for (int a = 0; a < 3; ++a) p[24 + a] = unit_to_byte(0.5 + kShC0 * dc[a]);
    }
    p[27] = unit_to_byte(opacity(i));
    const float* q = &m.quats[4 * i];
    const double norm =
        std::sqrt(double(q[0]) * q[0] + double(q[1]) * q[1] + double(q[2]) * q[2] + double(q[3]) * q[3]);
    for (int a = 0; a < 4; ++a) {
      const double u = norm > 0 && std::isfinite(norm) ? q[a] / norm : (a == 0 ? 1.0 : 0.0);
      p[28 + a] = static_cast<uint8_t>(std::clamp(std::lround(u * 128.0 + 128.0), 0L, 255L));
    }
  }
  return out;
}

size_t write_splat(const std::filesystem::path& path, const kernels::GaussianModel& model,
                   const SplatColouring& colouring) {
  const std::vector<uint8_t> bytes = encode_splat(model, colouring);
  write_file_atomic(path, [&](std::ostream& s) {
    s.write(reinterpret_cast<const char*>(bytes.data()), static_cast<std::streamsize>(bytes.size()));
  });
  return model.size();
}

}  // namespace litgs::io
