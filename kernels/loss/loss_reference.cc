#include "kernels/loss/loss_reference.h"

#include <cmath>
#include <limits>
#include <stdexcept>
#include <string>

#include "kernels/loss/loss_shared.h"

namespace litgs::kernels {
namespace {

void check_size(const char* who, const char* what, size_t got, size_t want) {
  if (got != want)
    throw std::invalid_argument(std::string(who) + ": " + what + " holds " + std::to_string(got) +
                                " values, expected " + std::to_string(want));
}

// Zero-padded separable blur of one [H][W] plane by the window (rows, then columns).
std::vector<double> blur(const std::vector<double>& window, const double* in, uint32_t w, uint32_t h) {
  const int r = SSIM_RADIUS;
  std::vector<double> rows(size_t{w} * h, 0.0), out(size_t{w} * h, 0.0);
  for (uint32_t y = 0; y < h; ++y)
    for (uint32_t x = 0; x < w; ++x) {
      double s = 0.0;
      for (int k = -r; k <= r; ++k) {
        const int xx = static_cast<int>(x) + k;
        if (xx >= 0 && xx < static_cast<int>(w)) s += window[k + r] * in[size_t{y} * w + xx];
      }
      rows[size_t{y} * w + x] = s;
    }
  for (uint32_t y = 0; y < h; ++y)
    for (uint32_t x = 0; x < w; ++x) {
      double s = 0.0;
      for (int k = -r; k <= r; ++k) {
        const int yy = static_cast<int>(y) + k;
        if (yy >= 0 && yy < static_cast<int>(h)) s += window[k + r] * rows[size_t(yy) * w + x];
      }
      out[size_t{y} * w + x] = s;
    }
  return out;
}

}  // namespace

std::vector<double> ssim_window() {
  std::vector<double> w(2 * SSIM_RADIUS + 1);
  double sum = 0.0;
  for (int k = -SSIM_RADIUS; k <= SSIM_RADIUS; ++k) {
    w[k + SSIM_RADIUS] = std::exp(-(k * k) / (2.0 * SSIM_SIGMA * SSIM_SIGMA));
    sum += w[k + SSIM_RADIUS];
  }
  for (double& v : w) v /= sum;
  return w;
}

PhotometricLossResult photometric_loss_reference(std::span<const double> image,
                                                 std::span<const double> target, uint32_t channels,
                                                 uint32_t width, uint32_t height, double lambda_ssim,
                                                 bool gradient) {
  static const char* who = "photometric_loss_reference";
  const size_t plane = size_t{width} * height;
  const size_t n = plane * channels;
  check_size(who, "image", image.size(), n);
  check_size(who, "target", target.size(), n);
  if (n == 0) throw std::invalid_argument(std::string(who) + ": empty image");
  if (!(lambda_ssim >= 0.0 && lambda_ssim <= 1.0))
    throw std::invalid_argument(std::string(who) + ": lambda_ssim must be in [0, 1]");
  const std::vector<double> window = ssim_window();
  const double inv_n = 1.0 / static_cast<double>(n);

  PhotometricLossResult result;
  if (gradient) result.grad.assign(n, 0.0);
  double sum_ssim = 0.0, sum_l1 = 0.0;
  std::vector<double> xx(plane), yy(plane), xy(plane), pa(plane), pb(plane), pc(plane);
  for (uint32_t c = 0; c < channels; ++c) {
    const double* x = image.data() + c * plane;
    const double* y = target.data() + c * plane;
    for (size_t i = 0; i < plane; ++i) {
      xx[i] = x[i] * x[i];
      yy[i] = y[i] * y[i];
      xy[i] = x[i] * y[i];
    }
    const auto mu_x = blur(window, x, width, height), mu_y = blur(window, y, width, height);
    const auto e_xx = blur(window, xx.data(), width, height), e_yy = blur(window, yy.data(), width, height);
    const auto e_xy = blur(window, xy.data(), width, height);
    for (size_t i = 0; i < plane; ++i) {
      const double mx = mu_x[i], my = mu_y[i];
      const double sxx = e_xx[i] - mx * mx, syy = e_yy[i] - my * my, sxy = e_xy[i] - mx * my;
      const double a1 = 2 * mx * my + SSIM_C1, a2 = 2 * sxy + SSIM_C2;
      const double b1 = mx * mx + my * my + SSIM_C1, b2 = sxx + syy + SSIM_C2;
      const double s = a1 * a2 / (b1 * b2);
      sum_ssim += s;
      sum_l1 += std::abs(x[i] - y[i]);
      // dL/dS = -lambda / N; partials of S w.r.t. mu_x, E[x^2], E[xy].
      const double g = -lambda_ssim * inv_n;
      pa[i] = g * 2 * (my * (a2 - a1) - mx * s * (b2 - b1)) / (b1 * b2);
      pb[i] = g * (-s / b2);
      pc[i] = g * 2 * a1 / (b1 * b2);
    }
    if (!gradient) continue;
    // mu_x(p) = sum_q G(p - q) x(q), E[x^2](p) = sum_q G(p - q) x(q)^2, E[xy](p) = sum_q G(p - q) x(q) y(q):
    // dL/dx(q) = (G*A)(q) + 2 x(q) (G*B)(q) + y(q) (G*C)(q), the zero-padded blur being self-adjoint.
    const auto ga = blur(window, pa.data(), width, height), gb = blur(window, pb.data(), width, height);
    const auto gc = blur(window, pc.data(), width, height);
    double* out = result.grad.data() + c * plane;
    for (size_t i = 0; i < plane; ++i) {
      const double d = x[i] - y[i];
      const double sign = d > 0 ? 1.0 : d < 0 ? -1.0 : 0.0;
      out[i] = ga[i] + 2 * x[i] * gb[i] + y[i] * gc[i] + (1.0 - lambda_ssim) * inv_n * sign;
    }
  }
  result.mean_ssim = sum_ssim * inv_n;
  result.mean_l1 = sum_l1 * inv_n;
  result.loss = (1.0 - lambda_ssim) * result.mean_l1 + lambda_ssim * (1.0 - result.mean_ssim);
  return result;
}

GeometricLossResult geometric_loss_reference(std::span<const double> depth, std::span<const float> points,
                                             std::span<const float> normals, uint32_t width, uint32_t height,
                                             double fx, double fy, double cx, double cy, uint32_t valid_count,
                                             double robust_scale_m) {
  static const char* who = "geometric_loss_reference";
  const size_t n = size_t{width} * height;
  check_size(who, "depth", depth.size(), n);
  check_size(who, "points", points.size(), 4 * n);
  check_size(who, "normals", normals.size(), 4 * n);
  GeometricLossResult result;
  result.grad_depth.assign(n, 0.0);
  if (valid_count == 0) return result;
  const double inv_valid = 1.0 / valid_count;
  double sum = 0.0;
  for (size_t i = 0; i < n; ++i) {
    const double d = depth[i];
    if (!(points[4 * i + 3] > 0.5f) || !(d > 0.0) || !std::isfinite(d)) continue;  // see geometric_loss.h
    const double u = static_cast<double>(i % width) + 0.5, v = static_cast<double>(i / width) + 0.5;
    const double ray[3] = {(u - cx) / fx, (v - cy) / fy, 1.0};
    double n_ray = 0.0, n_p = 0.0;
    for (int a = 0; a < 3; ++a) {
      n_ray += normals[4 * i + a] * ray[a];
      n_p += static_cast<double>(normals[4 * i + a]) * points[4 * i + a];
    }
    const double r = n_p - d * n_ray;
    const double s2 = robust_scale_m * robust_scale_m, x = s2 > 0 ? r * r / s2 : 0.0;
    sum += s2 > 0 ? s2 * std::log1p(x) : r * r;
    result.grad_depth[i] = inv_valid * (-2.0 * r * n_ray) / (1.0 + x);
    ++result.counted;
  }
  result.loss = sum * inv_valid;
  return result;
}

double ssim_reference(std::span<const float> image, std::span<const float> target, uint32_t channels,
                      uint32_t width, uint32_t height) {
  const std::vector<double> x(image.begin(), image.end()), y(target.begin(), target.end());
  return photometric_loss_reference(x, y, channels, width, height, 1.0, false).mean_ssim;
}

double psnr(std::span<const float> image, std::span<const float> target, double data_range) {
  check_size("psnr", "target", target.size(), image.size());
  if (image.empty()) throw std::invalid_argument("psnr: empty image");
  double se = 0.0;
  for (size_t i = 0; i < image.size(); ++i) {
    const double d = static_cast<double>(image[i]) - target[i];
    se += d * d;
  }
  const double mse = se / static_cast<double>(image.size());
  if (mse == 0.0) return std::numeric_limits<double>::infinity();
  return 10.0 * std::log10(data_range * data_range / mse);
}

}  // namespace litgs::kernels
