#include "kernels/loss/geometric_loss.h"

#include <cmath>
#include <stdexcept>
#include <string>

#include "kernels/device_growth.h"
#include "kernels/elementwise.h"
#include "kernels/loss/loss_shared.h"

namespace litgs::kernels {

using engine::Access;

GeometricLoss::GeometricLoss(engine::Context& context) : context_(&context), sum_(context) {
  kernel_ =
      loss_detail::make_kernel(context, "loss/geometric", GEOMETRIC_BINDING_COUNT, sizeof(GeometricParams));
}

GeometricLoss::~GeometricLoss() = default;

void GeometricLoss::reserve(uint32_t width, uint32_t height) {
  const uint64_t n = uint64_t{width} * height;
  grow(*context_, terms_buf_, 2 * n, "loss: geometric terms");
  sum_.reserve(n);
}

uint32_t GeometricLoss::count_valid(std::span<const float> points) {
  if (points.size() % 4 != 0)
    throw std::invalid_argument("GeometricLoss::count_valid: " + std::to_string(points.size()) +
                                " floats is not a [H][W][4] map");
  uint32_t count = 0;
  for (size_t i = 3; i < points.size(); i += 4) count += points[i] > 0.5f ? 1 : 0;
  return count;
}

uint32_t GeometricLoss::count_valid_planes(std::span<const float> planes) {
  if (planes.size() % 4 != 0)
    throw std::invalid_argument("GeometricLoss::count_valid_planes: " + std::to_string(planes.size()) +
                                " floats is not a [H][W][4] map");
  uint32_t count = 0;
  for (size_t i = 0; i < planes.size(); i += 4)
    count += planes[i] * planes[i] + planes[i + 1] * planes[i + 1] + planes[i + 2] * planes[i + 2] > 0.25f;
  return count;
}

std::vector<float> GeometricLoss::pack_plane_targets(std::span<const float> points,
                                                     std::span<const float> normals) {
  if (points.size() % 4 != 0 || normals.size() != points.size())
    throw std::invalid_argument("GeometricLoss::pack_plane_targets: a point map of " +
                                std::to_string(points.size()) + " floats and a normal map of " +
                                std::to_string(normals.size()) + " (need two [H][W][4] maps of one size)");
  std::vector<float> planes(points.size(), 0.0f);
  for (size_t i = 0; i < points.size(); i += 4) {
    if (!(points[i + 3] > 0.5f)) continue;
    double offset = 0;
    for (size_t k = 0; k < 3; ++k) {
      planes[i + k] = normals[i + k];
      offset += double{normals[i + k]} * points[i + k];
    }
    planes[i + 3] = static_cast<float>(offset);
  }
  return planes;
}

void GeometricLoss::record(engine::Sequence& sequence, const engine::Buffer& depth,
                           const engine::Buffer& planes, uint32_t width, uint32_t height, float fx, float fy,
                           float cx, float cy, uint32_t valid_count, float weight, float robust_scale_m,
                           const engine::Buffer& grad_depth, const engine::Buffer& loss_out,
                           uint32_t loss_slot) {
  static const char* who = "GeometricLoss::record";
  if (width == 0 || height == 0)
    throw std::invalid_argument(std::string(who) + ": view size " + std::to_string(width) + "x" +
                                std::to_string(height) + " is empty");
  if (!(std::isfinite(fx) && std::isfinite(fy) && std::isfinite(cx) && std::isfinite(cy) && fx > 0 && fy > 0))
    throw std::invalid_argument(std::string(who) + ": intrinsics fx " + std::to_string(fx) + " fy " +
                                std::to_string(fy) + " cx " + std::to_string(cx) + " cy " +
                                std::to_string(cy) + " (need finite values, fx and fy > 0)");
  if (!std::isfinite(weight)) throw std::invalid_argument(std::string(who) + ": weight is not finite");
  if (!(robust_scale_m >= 0) || !std::isfinite(robust_scale_m))
    throw std::invalid_argument(std::string(who) + ": robust_scale_m must be finite and >= 0 (0: squares)");
  const uint64_t n = uint64_t{width} * height;
  if (valid_count > n)
    throw std::invalid_argument(std::string(who) + ": valid_count " + std::to_string(valid_count) +
                                " exceeds the " + std::to_string(n) + " pixels");
  loss_detail::check_binding(who, "depth", depth, n * sizeof(float));
  loss_detail::check_binding(who, "planes", planes, 4 * n * sizeof(float));
  loss_detail::check_binding(who, "grad_depth", grad_depth, n * sizeof(float));
  loss_detail::check_binding(who, "loss_out", loss_out, (uint64_t{loss_slot} + kOutputs) * sizeof(float));
  const engine::Groups groups = elementwise_groups(*context_, n, who);
  reserve(width, height);

  GeometricParams p{};
  p.width = width;
  p.height = height;
  p.count = static_cast<uint32_t>(n);
  p.fx = fx;
  p.fy = fy;
  p.cx = cx;
  p.cy = cy;
  p.inv_valid = valid_count > 0 ? static_cast<float>(1.0 / valid_count) : 0.0f;
  p.weight = weight;
  p.inv_scale2 =
      robust_scale_m > 0 ? static_cast<float>(1.0 / (double{robust_scale_m} * robust_scale_m)) : 0.0f;
  sequence.dispatch(*kernel_, groups,
                    {{GEOMETRIC_BINDING_DEPTH, &depth, Access::kRead},
                     {GEOMETRIC_BINDING_PLANES, &planes, Access::kRead},
                     {GEOMETRIC_BINDING_GRAD, &grad_depth, Access::kWrite},
                     {GEOMETRIC_BINDING_TERMS, &terms_buf_->buffer(), Access::kWrite}},
                    p);
  ReduceParams r{};
  r.slot = loss_slot;
  r.outputs = kOutputs;
  r.w00 = p.inv_valid;  // L_geo = sum r^2 / N_valid
  r.w11 = 1.0f;         // pixels that counted
  sum_.record(sequence, terms_buf_->buffer(), n, r, loss_out);
}

}  // namespace litgs::kernels
