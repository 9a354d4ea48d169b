#include "kernels/loss/photometric_loss.h"

#include <cmath>
#include <stdexcept>
#include <string>

#include "kernels/device_growth.h"
#include "kernels/elementwise.h"
#include "kernels/loss/loss_shared.h"
#include "kernels/splat/splat_shared.h"

namespace litgs::kernels {

using engine::Access;

void PhotometricLossOptions::check() const {
  if (!(lambda_ssim >= 0.0f && lambda_ssim <= 1.0f))
    throw std::invalid_argument("PhotometricLossOptions::lambda_ssim = " + std::to_string(lambda_ssim) +
                                ", must be in [0, 1]");
}

PhotometricLoss::PhotometricLoss(engine::Context& context, uint32_t channels, PhotometricLossOptions options)
    : context_(&context), channels_(channels), options_(options), sum_(context) {
  options_.check();
  if (channels < 1 || channels > SPLAT_MAX_CHANNELS)
    throw std::invalid_argument("PhotometricLoss: channels = " + std::to_string(channels) + ", must be 1.." +
                                std::to_string(SPLAT_MAX_CHANNELS));
  // The window taps read their inputs as texels (loss_shared.h): on CPU drivers a fetch is a vector gather,
  // a storage-buffer load a loop over the lanes.
  const VkFormat f1 = VK_FORMAT_R32_SFLOAT, f4 = VK_FORMAT_R32G32B32A32_SFLOAT;
  moments_ = loss_detail::make_kernel(context, "loss/ssim_moments_h", SSIM_MOMENTS_BINDING_COUNT,
                                      sizeof(PhotometricParams), {},
                                      {{SSIM_MOMENTS_BINDING_IMAGE, f1}, {SSIM_MOMENTS_BINDING_TARGET, f1}});
  pixel_ = loss_detail::make_kernel(context, "loss/ssim_pixel", SSIM_PIXEL_BINDING_COUNT,
                                    sizeof(PhotometricParams), {},
                                    {{SSIM_PIXEL_BINDING_IMAGE, f1},
                                     {SSIM_PIXEL_BINDING_TARGET, f1},
                                     {SSIM_PIXEL_BINDING_MOMENTS4, f4},
                                     {SSIM_PIXEL_BINDING_MOMENTS1, f1}});
  partials_h_ = loss_detail::make_kernel(context, "loss/ssim_partials_h", SSIM_PARTIALS_BINDING_COUNT,
                                         sizeof(PhotometricParams), {}, {{SSIM_PARTIALS_BINDING_IN, f4}});
  backward_ = loss_detail::make_kernel(context, "loss/ssim_backward", SSIM_BACKWARD_BINDING_COUNT,
                                       sizeof(PhotometricParams), {},
                                       {{SSIM_BACKWARD_BINDING_IMAGE, f1},
                                        {SSIM_BACKWARD_BINDING_TARGET, f1},
                                        {SSIM_BACKWARD_BINDING_PARTIALS, f4}});
}

PhotometricLoss::~PhotometricLoss() = default;

void PhotometricLoss::reserve(uint32_t width, uint32_t height) {
  const uint64_t n = uint64_t{channels_} * width * height;
  grow(*context_, moments4_buf_, 4 * n, "loss: ssim moments (4)");
  grow(*context_, moments1_buf_, n, "loss: ssim moments (xy)");
  grow(*context_, partials_buf_, 4 * n, "loss: ssim partials");
  grow(*context_, terms_buf_, 2 * n, "loss: photometric terms");
  sum_.reserve(n);
}

void PhotometricLoss::record(engine::Sequence& sequence, const engine::Buffer& image,
                             const engine::Buffer& target, uint32_t width, uint32_t height, float weight,
                             const engine::Buffer& grad_image, const engine::Buffer& loss_out,
                             uint32_t loss_slot) {
  static const char* who = "PhotometricLoss::record";
  if (width == 0 || height == 0)
    throw std::invalid_argument(std::string(who) + ": image size " + std::to_string(width) + "x" +
                                std::to_string(height) + " is empty");
  if (!std::isfinite(weight)) throw std::invalid_argument(std::string(who) + ": weight is not finite");
  const uint64_t n = uint64_t{channels_} * width * height;
  if (n > 0xFFFFFFFFull / 4) throw std::length_error(std::string(who) + ": image too large");
  const uint64_t bytes = n * sizeof(float);
  loss_detail::check_binding(who, "image", image, bytes);
  loss_detail::check_binding(who, "target", target, bytes);
  loss_detail::check_binding(who, "grad_image", grad_image, bytes);
  loss_detail::check_binding(who, "loss_out", loss_out, (uint64_t{loss_slot} + kOutputs) * sizeof(float));
  const engine::Groups groups = elementwise_groups(*context_, n, who);
  reserve(width, height);
  loss_detail::check_binding(who, "ssim moments (scratch)", moments4_buf_->buffer(), 4 * bytes);

  PhotometricParams p{};
  p.width = width;
  p.height = height;
  p.count = static_cast<uint32_t>(n);
  p.lambda_ssim = options_.lambda_ssim;
  p.inv_count = static_cast<float>(1.0 / static_cast<double>(n));
  p.weight = weight;

  const engine::Buffer& moments4 = moments4_buf_->buffer();
  const engine::Buffer& moments1 = moments1_buf_->buffer();
  const engine::Buffer& partials = partials_buf_->buffer();
  const engine::Buffer& terms = terms_buf_->buffer();
  sequence.dispatch(*moments_, groups,
                    {{SSIM_MOMENTS_BINDING_IMAGE, &image, Access::kRead},
                     {SSIM_MOMENTS_BINDING_TARGET, &target, Access::kRead},
                     {SSIM_MOMENTS_BINDING_OUT4, &moments4, Access::kWrite},
                     {SSIM_MOMENTS_BINDING_OUT1, &moments1, Access::kWrite}},
                    p);
  sequence.dispatch(*pixel_, groups,
                    {{SSIM_PIXEL_BINDING_IMAGE, &image, Access::kRead},
                     {SSIM_PIXEL_BINDING_TARGET, &target, Access::kRead},
                     {SSIM_PIXEL_BINDING_MOMENTS4, &moments4, Access::kRead},
                     {SSIM_PIXEL_BINDING_MOMENTS1, &moments1, Access::kRead},
                     {SSIM_PIXEL_BINDING_PARTIALS, &partials, Access::kWrite},
                     {SSIM_PIXEL_BINDING_TERMS, &terms, Access::kWrite}},
                    p);
  // The row blurs are dead after ssim_pixel: their buffer takes the blurred partials.
  sequence.dispatch(*partials_h_, groups,
                    {{SSIM_PARTIALS_BINDING_IN, &partials, Access::kRead},
                     {SSIM_PARTIALS_BINDING_OUT, &moments4, Access::kWrite}},
                    p);
  sequence.dispatch(*backward_, groups,
                    {{SSIM_BACKWARD_BINDING_IMAGE, &image, Access::kRead},
                     {SSIM_BACKWARD_BINDING_TARGET, &target, Access::kRead},
                     {SSIM_BACKWARD_BINDING_PARTIALS, &moments4, Access::kRead},
                     {SSIM_BACKWARD_BINDING_GRAD, &grad_image, Access::kWrite}},
                    p);

  // Sums of (1 - SSIM, |x - y|): L = lambda s0 / N + (1 - lambda) s1 / N; mean SSIM = 1 - s0 / N.
  const float lambda = options_.lambda_ssim;
  ReduceParams r{};
  r.slot = loss_slot;
  r.outputs = kOutputs;
  r.w00 = static_cast<float>(lambda / static_cast<double>(n));
  r.w01 = static_cast<float>((1.0 - lambda) / static_cast<double>(n));
  r.bias1 = 1.0f;
  r.w10 = -p.inv_count;
  r.w21 = p.inv_count;
  sum_.record(sequence, terms, n, r, loss_out);
}

}  // namespace litgs::kernels
