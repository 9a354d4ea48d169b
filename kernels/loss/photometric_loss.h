// The photometric training loss on the device:
//   L_pho = (1 - lambda_ssim) * mean|x - y| + lambda_ssim * (1 - mean SSIM(x, y))
// over every pixel and channel of an image x and a target y ([C][H][W] float, the rasterizer's layout).
// SSIM as 3DGS's ssim(): an 11x11 Gaussian window (sigma 1.5), C1 = 0.01^2, C2 = 0.03^2, per channel, zero
// padding at the borders (window sums near a border include zeros), averaged over all C*H*W values.
// The CPU double reference of the same math is kernels/loss/loss_reference.h.
#pragma once

#include <cstdint>
#include <memory>

#include "engine/buffer.h"
#include "engine/context.h"
#include "engine/kernel.h"
#include "engine/sequence.h"
#include "kernels/loss/loss_sum.h"

namespace litgs::kernels {

struct PhotometricLossOptions {
  // Weight of the D-SSIM term, in [0, 1]; 0 gives exactly the L1 loss, 1 only D-SSIM.
  float lambda_ssim = 0.2f;
  // Throws std::invalid_argument naming the bad field.
  void check() const;
};

class PhotometricLoss {
 public:
  // Outputs written from the loss slot: L_pho, mean SSIM, mean |x - y|.
  static constexpr uint32_t kOutputs = 3;

  // Builds the kernels for images of `channels` channels (1..4, as the rasterizer).
  PhotometricLoss(engine::Context& context, uint32_t channels, PhotometricLossOptions options = {});
  ~PhotometricLoss();

  // Allocates the scratch for images up to width x height now (record() grows it on demand otherwise).
  void reserve(uint32_t width, uint32_t height);

  // Records forward and backward into `sequence` (no submit):
  //   loss_out[loss_slot]     = L_pho (unweighted)
  //   loss_out[loss_slot + 1] = mean SSIM
  //   loss_out[loss_slot + 2] = mean |x - y|
  //   grad_image = weight * dL_pho/dx, [C][H][W], OVERWRITTEN (not accumulated): the photometric term is the
  //                only one with a gradient w.r.t. the image, so the trainer needs no clear before it.
  // image and target hold C*H*W floats ([C][H][W]), loss_out at least loss_slot + 3 floats; every buffer is
  // checked. At |x - y| = 0 the L1 term's gradient is 0. Scratch (11 * C*H*W floats) belongs to this
  // object and is shared by every record(): a record() that grows it (a larger image than any before; use
  // reserve()) frees the old scratch, so sequences recorded earlier must not be submitted again after it.
  void record(engine::Sequence& sequence, const engine::Buffer& image, const engine::Buffer& target,
              uint32_t width, uint32_t height, float weight, const engine::Buffer& grad_image,
              const engine::Buffer& loss_out, uint32_t loss_slot);

  uint32_t channels() const { return channels_; }
  const PhotometricLossOptions& options() const { return options_; }

 private:
  engine::Context* context_;
  uint32_t channels_;
  PhotometricLossOptions options_;
  std::unique_ptr<engine::Kernel> moments_, pixel_, partials_h_, backward_;
  loss_detail::LossSum sum_;
  // moments4 [N][4] and moments1 [N]: row blurs (moments4 is reused for the blurred partials);
  // partials [N][4]; terms [N][2]. Vectors per element: one load per tap on CPU drivers, not one per map.
  std::unique_ptr<engine::DeviceArray<float>> moments4_buf_, moments1_buf_, partials_buf_, terms_buf_;
};

}  // namespace litgs::kernels
