#include "kernels/optim/adam.h"

#include <algorithm>
#include <cmath>
#include <stdexcept>
#include <string>

#include "kernels/elementwise.h"
#include "kernels/optim/optim_shared.h"
#include "kernels/spirv_registry.h"

namespace litgs::kernels {

namespace {

void require(bool ok, const char* field, double value, const char* rule) {
  if (!ok)
    throw std::invalid_argument(std::string("AdamOptions.") + field + " = " + std::to_string(value) + ": " +
                                rule);
}

}  // namespace

void AdamOptions::check() const {
  require(beta1 >= 0 && beta1 < 1, "beta1", beta1, "must be in [0, 1)");
  require(beta2 >= 0 && beta2 < 1, "beta2", beta2, "must be in [0, 1)");
  require(eps >= 0 && std::isfinite(eps), "eps", eps, "must be finite and >= 0");
  require(means_lr_init > 0 && std::isfinite(means_lr_init), "means_lr_init", means_lr_init, "must be > 0");
  require(means_lr_final > 0 && std::isfinite(means_lr_final), "means_lr_final", means_lr_final,
          "must be > 0");
  require(means_lr_delay_mult > 0 && means_lr_delay_mult <= 1, "means_lr_delay_mult", means_lr_delay_mult,
          "must be in (0, 1]");
  for (auto [name, v] : {std::pair{"sh_dc_lr", sh_dc_lr},
                         {"sh_rest_lr", sh_rest_lr},
                         {"opacity_lr", opacity_lr},
                         {"log_scales_lr", log_scales_lr},
                         {"quats_lr", quats_lr}})
    require(v >= 0 && std::isfinite(v), name, v, "must be finite and >= 0");
}

float AdamOptions::means_lr(uint32_t step, uint32_t max_steps, float extent) const {
  // 3DGS utils/general_utils.py get_expon_lr_func, in double.
  const double init = double{means_lr_init} * extent, final_lr = double{means_lr_final} * extent;
  if (init == 0.0 && final_lr == 0.0) return 0.0f;
  double delay_rate = 1.0;
  if (means_lr_delay_steps > 0)
    delay_rate = means_lr_delay_mult +
                 (1.0 - means_lr_delay_mult) *
                     std::sin(0.5 * M_PI * std::clamp(double(step) / means_lr_delay_steps, 0.0, 1.0));
  const double t = max_steps == 0 ? 1.0 : std::clamp(double(step) / max_steps, 0.0, 1.0);
  return static_cast<float>(delay_rate * std::exp(std::log(init) * (1.0 - t) + std::log(final_lr) * t));
}

LearningRates AdamOptions::rates(uint32_t step, uint32_t max_steps, float extent) const {
  return {means_lr(step, max_steps, extent), log_scales_lr, quats_lr, opacity_lr, sh_dc_lr, sh_rest_lr};
}

void check_binding(const engine::Buffer& buffer, uint64_t count, uint64_t value_bytes, const char* what) {
  if (buffer.size_bytes() < count * value_bytes)
    throw std::out_of_range(std::string(what) + ": buffer '" + buffer.name() + "' holds " +
                            std::to_string(buffer.size_bytes() / value_bytes) + " values, needs " +
                            std::to_string(count));
}

AdamParams adam_params(const AdamOptions& options, uint32_t step, float lr, float lr_rest, uint32_t count,
                       uint32_t period, uint32_t lead, uint32_t counter_slot) {
  AdamParams p{};
  p.count = count;
  p.period = period;
  p.lead = lead;
  p.counter_slot = counter_slot;
  p.lr = lr;
  p.lr_rest = lr_rest;
  p.beta1 = options.beta1;
  p.beta2 = options.beta2;
  p.eps = options.eps;
  p.bias_correction1 = static_cast<float>(1.0 - std::pow(double{options.beta1}, double(step)));
  p.sqrt_bias_correction2 =
      static_cast<float>(std::sqrt(1.0 - std::pow(double{options.beta2}, double(step))));
  return p;
}

AdamKernel::AdamKernel(engine::Context& context) : context_(&context) {
  engine::KernelDesc desc;
  desc.name = "optim/adam";
  desc.spirv = spirv("optim/adam");
  desc.binding_count = ADAM_BINDING_COUNT;
  desc.push_constant_bytes = sizeof(AdamParams);
  kernel_ = std::make_unique<engine::Kernel>(context, std::move(desc));
}

AdamKernel::~AdamKernel() = default;

void AdamKernel::record(engine::Sequence& sequence, const Target& t, uint64_t count,
                        const AdamOptions& options, uint32_t step, float lr, uint32_t counter_slot,
                        float lr_rest, uint32_t period, uint32_t lead) const {
  if (step == 0) throw std::invalid_argument("AdamKernel::record: step counts from 1");
  if (counter_slot >= ADAM_COUNTER_SLOTS) throw std::invalid_argument("AdamKernel::record: bad counter slot");
  if (period == 0 || lead > period)
    throw std::invalid_argument("AdamKernel::record: need 0 < period, lead <= period");
  if (count > 0xFFFFFFFFull) throw std::length_error("AdamKernel::record: more than 2^32 elements");
  check_binding(*t.params, count, 4, "adam params");
  check_binding(*t.grads, count, 4, "adam grads");
  check_binding(*t.exp_avg, count, 4, "adam exp_avg");
  check_binding(*t.exp_avg_sq, count, 4, "adam exp_avg_sq");
  check_binding(*t.counters, ADAM_COUNTER_SLOTS, 4, "adam counters");
  const AdamParams p =
      adam_params(options, step, lr, lr_rest, static_cast<uint32_t>(count), period, lead, counter_slot);
  using engine::Access;
  sequence.dispatch(*kernel_, elementwise_groups(*context_, count, "optim/adam"),
                    {{ADAM_BINDING_PARAMS, t.params, Access::kReadWrite},
                     {ADAM_BINDING_GRADS, t.grads, Access::kRead},
                     {ADAM_BINDING_EXP_AVG, t.exp_avg, Access::kReadWrite},
                     {ADAM_BINDING_EXP_AVG_SQ, t.exp_avg_sq, Access::kReadWrite},
                     {ADAM_BINDING_COUNTERS, t.counters, Access::kReadWrite}},
                    p);
}

}  // namespace litgs::kernels
