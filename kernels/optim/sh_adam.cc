#include "kernels/optim/sh_adam.h"

#include <stdexcept>

#include "kernels/elementwise.h"
#include "kernels/optim/optim_shared.h"
#include "kernels/splat/splat_shared.h"
#include "kernels/subgroup_kernel.h"

namespace litgs::kernels {

ShAdamKernel::ShAdamKernel(engine::Context& context, uint32_t channels)
    : context_(&context), channels_(channels) {
  if (channels == 0 || channels > SPLAT_MAX_CHANNELS)
    throw std::invalid_argument("ShAdamKernel: channels must be 1.." + std::to_string(SPLAT_MAX_CHANNELS));
  kernel_ = make_kernel(context, "optim/sh_adam", SH_ADAM_BINDING_COUNT, sizeof(ShAdamParams),
                        {{1, channels}});  // CHANNELS: the gradient rows' stride
}

ShAdamKernel::~ShAdamKernel() = default;

void ShAdamKernel::record(engine::Sequence& sequence, const Target& t, uint32_t gaussians, uint32_t sh_coeffs,
                          const SplatCamera& camera, const AdamOptions& options, uint32_t step, float lr_dc,
                          float lr_rest, uint32_t counter_slot) const {
  if (step == 0) throw std::invalid_argument("ShAdamKernel::record: step counts from 1");
  if (counter_slot >= ADAM_COUNTER_SLOTS)
    throw std::invalid_argument("ShAdamKernel::record: bad counter slot");
  if (sh_coeffs == 0 || sh_coeffs > SPLAT_MAX_SH_COEFFS || camera.sh_degree > 3 ||
      (camera.sh_degree + 1) * (camera.sh_degree + 1) > sh_coeffs)
    throw std::invalid_argument("ShAdamKernel::record: the active SH degree needs more coefficients than " +
                                std::to_string(sh_coeffs));
  const uint64_t values = uint64_t{gaussians} * sh_coeffs * channels_;
  check_binding(*t.sh, values, 4, "sh adam: sh");
  check_binding(*t.exp_avg, values, 4, "sh adam: exp_avg");
  check_binding(*t.exp_avg_sq, values, 4, "sh adam: exp_avg_sq");
  check_binding(*t.counters, ADAM_COUNTER_SLOTS, 4, "sh adam: counters");
  check_binding(*t.means, uint64_t{gaussians} * 3, 4, "sh adam: means");
  check_binding(*t.tile_rects, uint64_t{gaussians} * 2, 4, "sh adam: tile rects");
  check_binding(*t.grad2d, uint64_t{gaussians} * (SPLAT_GRAD2D_FIXED + channels_), 4, "sh adam: grad2d");
  ShAdamParams p{};
  p.adam =
      adam_params(options, step, lr_dc, lr_rest, gaussians, sh_coeffs * channels_, channels_, counter_slot);
  const glm::dvec3 centre = -(glm::transpose(camera.R_cam_world) * camera.t_cam_world);
  for (int a = 0; a < 3; ++a) p.centre[a] = static_cast<float>(centre[a]);
  p.sh_degree = camera.sh_degree;
  p.sh_coeffs = sh_coeffs;
  using engine::Access;
  sequence.dispatch(*kernel_, elementwise_groups(*context_, gaussians, "optim/sh_adam"),
                    {{SH_ADAM_BINDING_SH, t.sh, Access::kReadWrite},
                     {SH_ADAM_BINDING_EXP_AVG, t.exp_avg, Access::kReadWrite},
                     {SH_ADAM_BINDING_EXP_AVG_SQ, t.exp_avg_sq, Access::kReadWrite},
                     {SH_ADAM_BINDING_COUNTERS, t.counters, Access::kReadWrite},
                     {SH_ADAM_BINDING_MEANS, t.means, Access::kRead},
                     {SH_ADAM_BINDING_TILE_RECTS, t.tile_rects, Access::kRead},
                     {SH_ADAM_BINDING_GRAD2D, t.grad2d, Access::kRead}},
                    p);
}

}  // namespace litgs::kernels
