// The LiDAR point-to-plane training loss on the device (the method's geometric term):
//   L_geo = (1 / N_valid) * sum_i rho(n_i . (P_i - D(u_i) K^-1 [u_i + 0.5, v_i + 0.5, 1]))      [metres^2]
// with rho(r) = r^2 (robust scale s = 0: the method's squared residual) or the Cauchy kernel
// rho(r) = s^2 log(1 + r^2 / s^2), which is r^2 for |r| << s and grows only logarithmically beyond: a pixel
// whose LiDAR surface is not the one it sees (a farther surface between a nearer one's sparse points, a disc
// reaching over an edge) pulls with a force that falls as s^2 / r instead of growing as r.
// over pixels i that carry a LiDAR point P_i (camera frame, metres) and its unit plane normal n_i; D is the
// rendered expected depth (metres, camera z). N_valid is the number of pixels with a point (the host counts
// it once per view: count_valid()), so the loss is a mean over LiDAR pixels and does not jump as rendered
// coverage changes.
//
// Pixels where nothing was rendered (D <= 0 or not finite; the rasterizer writes D = 0 where the
// accumulated alpha is below SPLAT_MIN_DEPTH_WEIGHT) are SKIPPED: they add 0 to the sum and get a zero
// gradient, but stay in N_valid. Counting them with D = 0 would add (n . P)^2 -- the plane's distance from
// the camera centre, metres squared -- a constant that dwarfs the real residuals and carries no gradient
// (the rasterizer's depth has none where nothing is rendered). The reference does the same.
// The CPU double reference of the same math is kernels/loss/loss_reference.h.
#pragma once

#include <cstdint>
#include <memory>
#include <span>
#include <vector>

#include "engine/buffer.h"
#include "engine/context.h"
#include "engine/kernel.h"
#include "engine/sequence.h"
#include "kernels/loss/loss_sum.h"

namespace litgs::kernels {

class GeometricLoss {
 public:
  // Outputs written from the loss slot: L_geo (m^2), and the number of pixels that counted (a valid point
  // and a rendered depth), as a float.
  static constexpr uint32_t kOutputs = 2;

  explicit GeometricLoss(engine::Context& context);
  ~GeometricLoss();

  // Allocates the scratch for views up to width x height now (record() grows it on demand otherwise).
  void reserve(uint32_t width, uint32_t height);

  // Records forward and backward into `sequence` (no submit):
  //   loss_out[loss_slot]     = L_geo (unweighted, metres^2; robust_scale_m = s of the kernel, 0: squares)
  //   loss_out[loss_slot + 1] = pixels that counted
  //   grad_depth = weight * dL_geo/dD, [H][W] (metres^2 per metre), OVERWRITTEN (not accumulated).
  // depth holds H*W floats, planes H*W*4 (pack_plane_targets), loss_out at least loss_slot + 2 floats;
  // every buffer is checked. valid_count = 0: loss 0 and a zero gradient.
  // Intrinsics in pixels; pixel (u, v) has its centre at (u + 0.5, v + 0.5). Scratch as PhotometricLoss.
  void record(engine::Sequence& sequence, const engine::Buffer& depth, const engine::Buffer& planes,
              uint32_t width, uint32_t height, float fx, float fy, float cx, float cy, uint32_t valid_count,
              float weight, float robust_scale_m, const engine::Buffer& grad_depth,
              const engine::Buffer& loss_out, uint32_t loss_slot);

  // The kernel's per-pixel target [H][W][4] (n_x, n_y, n_z, n . P) from a point map [H][W][4] (x y z
  // valid) and a normal map [H][W][4] (nx ny nz 0): half the bytes of the two, since the residual needs only
  // n and n . P; n . P is taken in double. Pixels whose valid flag is not above 0.5 get zeros.
  // std::invalid_argument when the maps are not [H][W][4] of the same size.
  static std::vector<float> pack_plane_targets(std::span<const float> points, std::span<const float> normals);

  // N_valid of a point map [H][W][4] (valid flag, element 3, above 0.5) or of packed plane targets (a
  // non-zero normal): the same count for the same pixels.
  static uint32_t count_valid(std::span<const float> points);
  static uint32_t count_valid_planes(std::span<const float> planes);

 private:
  engine::Context* context_;
  std::unique_ptr<engine::Kernel> kernel_;
  loss_detail::LossSum sum_;
  std::unique_ptr<engine::DeviceArray<float>> terms_buf_;  // [H][W][2]
};

}  // namespace litgs::kernels
