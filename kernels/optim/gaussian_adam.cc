#include "kernels/optim/gaussian_adam.h"

#include <bit>
#include <cmath>
#include <stdexcept>
#include <string>

#include "kernels/elementwise.h"
#include "kernels/optim/optim_shared.h"
#include "kernels/optim/training_state.h"
#include "kernels/splat/rasterizer.h"
#include "kernels/splat/splat_shared.h"
#include "kernels/subgroup_kernel.h"

namespace litgs::kernels {

static_assert(kMeans == 0 && kLogScales == 1 && kQuats == 2 && kOpacityLogits == 3 && kSh == 4 &&
                  kParamGroupCount == GAUSSIAN_ADAM_GROUPS,
              "gaussian_adam.comp numbers the groups and their counter slots in ParamGroup order");

GaussianAdamKernel::GaussianAdamKernel(engine::Context& context, uint32_t channels,
                                       const AdamOptions& options)
    : context_(&context), channels_(channels), options_(options) {
  if (channels == 0 || channels > SPLAT_MAX_CHANNELS)
    throw std::invalid_argument("GaussianAdamKernel: channels must be 1.." +
                                std::to_string(SPLAT_MAX_CHANNELS));
  options.check();
  kernel_ =
      make_kernel(context, "optim/gaussian_adam", GAUSSIAN_ADAM_BINDING_COUNT, sizeof(GaussianAdamParams),
                  {{1, channels},
                   {2, std::bit_cast<uint32_t>(options.beta1)},
                   {3, std::bit_cast<uint32_t>(options.beta2)},
                   {4, std::bit_cast<uint32_t>(options.eps)}},
                  {{GAUSSIAN_ADAM_BINDING_GRAD2D, VK_FORMAT_R32_SFLOAT}});
}

GaussianAdamKernel::~GaussianAdamKernel() = default;

void GaussianAdamKernel::record(engine::Sequence& sequence, const Target& t, uint32_t gaussians,
                                uint32_t sh_coeffs, const SplatCamera& camera, const AdamOptions& options,
                                uint32_t step, const LearningRates& lr,
                                const RegularizationWeights& regularization) const {
  static const char* who = "GaussianAdamKernel::record";
  if (step == 0) throw std::invalid_argument(std::string(who) + ": step counts from 1");
  if (options.beta1 != options_.beta1 || options.beta2 != options_.beta2 || options.eps != options_.eps)
    throw std::invalid_argument(std::string(who) + ": beta1, beta2 or eps differ from the kernel's");
  if (sh_coeffs == 0 || sh_coeffs > SPLAT_MAX_SH_COEFFS || camera.sh_degree > 3 ||
      (camera.sh_degree + 1) * (camera.sh_degree + 1) > sh_coeffs)
    throw std::invalid_argument(std::string(who) + ": the active SH degree needs more coefficients than " +
                                std::to_string(sh_coeffs));
  const uint64_t n = gaussians;
  const uint64_t widths[GAUSSIAN_ADAM_GROUPS] = {3, 3, 4, 1, uint64_t{sh_coeffs} * channels_};
  for (uint32_t g = 0; g < GAUSSIAN_ADAM_GROUPS; ++g) {
    const std::string group = kParamGroupNames[g];
    check_binding(*t.params[g], n * widths[g], 4, ("gaussian adam: " + group).c_str());
    check_binding(*t.exp_avg[g], n * widths[g], 4, ("gaussian adam: exp_avg " + group).c_str());
    check_binding(*t.exp_avg_sq[g], n * widths[g], 4, ("gaussian adam: exp_avg_sq " + group).c_str());
  }
  check_binding(*t.counters, ADAM_COUNTER_SLOTS, 4, "gaussian adam: counters");
  check_binding(*t.tile_rects, n * 2, 4, "gaussian adam: tile rects");
  check_binding(*t.grad2d, n * (SPLAT_GRAD2D_FIXED + channels_), 4, "gaussian adam: grad2d");

  const SplatView view = make_splat_view(camera, gaussians, sh_coeffs);
  GaussianAdamParams p{};
  for (int k = 0; k < 9; ++k) p.rot[k] = view.rot[k];
  for (int k = 0; k < 3; ++k) p.trans[k] = view.trans[k];
  p.fx = view.fx;
  p.fy = view.fy;
  p.cx = view.cx;
  p.cy = view.cy;
  p.near_m = view.near_m;
  p.width = view.width;
  p.height = view.height;
  p.count = gaussians;
  p.sh_degree = view.sh_degree;
  p.sh_coeffs = sh_coeffs;
  const float rates[GAUSSIAN_ADAM_GROUPS] = {lr.means, lr.log_scales, lr.quats, lr.opacity_logits, lr.sh_dc};
  for (uint32_t g = 0; g < GAUSSIAN_ADAM_GROUPS; ++g) p.lr[g] = rates[g];
  p.lr_sh_rest = lr.sh_rest;
  // The bias corrections exactly as adam.comp gets them.
  const AdamParams step_params = adam_params(options, step, 0.0f, 0.0f, gaussians, 1, 1, 0);
  p.bias_correction1 = step_params.bias_correction1;
  p.sqrt_bias_correction2 = step_params.sqrt_bias_correction2;
  p.opacity_reg = regularization.opacity;
  p.scale_reg = regularization.scale;

  using engine::Access;
  sequence.dispatch(
      *kernel_, elementwise_groups(*context_, n, "optim/gaussian_adam"),
      {{GAUSSIAN_ADAM_BINDING_MEANS, t.params[kMeans], Access::kReadWrite},
       {GAUSSIAN_ADAM_BINDING_LOG_SCALES, t.params[kLogScales], Access::kReadWrite},
       {GAUSSIAN_ADAM_BINDING_QUATS, t.params[kQuats], Access::kReadWrite},
       {GAUSSIAN_ADAM_BINDING_OPACITY_LOGITS, t.params[kOpacityLogits], Access::kReadWrite},
       {GAUSSIAN_ADAM_BINDING_SH, t.params[kSh], Access::kReadWrite},
       {GAUSSIAN_ADAM_BINDING_EXP_AVG + kMeans, t.exp_avg[kMeans], Access::kReadWrite},
       {GAUSSIAN_ADAM_BINDING_EXP_AVG + kLogScales, t.exp_avg[kLogScales], Access::kReadWrite},
       {GAUSSIAN_ADAM_BINDING_EXP_AVG + kQuats, t.exp_avg[kQuats], Access::kReadWrite},
       {GAUSSIAN_ADAM_BINDING_EXP_AVG + kOpacityLogits, t.exp_avg[kOpacityLogits], Access::kReadWrite},
       {GAUSSIAN_ADAM_BINDING_EXP_AVG + kSh, t.exp_avg[kSh], Access::kReadWrite},
       {GAUSSIAN_ADAM_BINDING_EXP_AVG_SQ + kMeans, t.exp_avg_sq[kMeans], Access::kReadWrite},
       {GAUSSIAN_ADAM_BINDING_EXP_AVG_SQ + kLogScales, t.exp_avg_sq[kLogScales], Access::kReadWrite},
       {GAUSSIAN_ADAM_BINDING_EXP_AVG_SQ + kQuats, t.exp_avg_sq[kQuats], Access::kReadWrite},
       {GAUSSIAN_ADAM_BINDING_EXP_AVG_SQ + kOpacityLogits, t.exp_avg_sq[kOpacityLogits], Access::kReadWrite},
       {GAUSSIAN_ADAM_BINDING_EXP_AVG_SQ + kSh, t.exp_avg_sq[kSh], Access::kReadWrite},
       {GAUSSIAN_ADAM_BINDING_COUNTERS, t.counters, Access::kReadWrite},
       {GAUSSIAN_ADAM_BINDING_TILE_RECTS, t.tile_rects, Access::kRead},
       {GAUSSIAN_ADAM_BINDING_GRAD2D, t.grad2d, Access::kRead}},
      p);
}

}  // namespace litgs::kernels
