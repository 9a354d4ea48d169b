#include "kernels/optim/training_state.h"

#include <stdexcept>
#include <string>

namespace litgs::kernels {

const std::vector<float>& group_values(const GaussianModel& m, uint32_t group) {
  switch (group) {
    case kMeans:
      return m.means;
    case kLogScales:
      return m.log_scales;
    case kQuats:
      return m.quats;
    case kOpacityLogits:
      return m.opacity_logits;
    case kSh:
      return m.sh;
    default:
      throw std::out_of_range("group_values: no parameter group " + std::to_string(group));
  }
}

std::vector<float>& group_values(GaussianModel& m, uint32_t group) {
  return const_cast<std::vector<float>&>(group_values(static_cast<const GaussianModel&>(m), group));
}

TrainingState TrainingState::fresh(const GaussianModel& model) {
  model.check();
  TrainingState s;
  s.model = model;
  for (uint32_t g = 0; g < kParamGroupCount; ++g) {
    const size_t values = group_values(model, g).size();
    s.exp_avg[g].assign(values, 0.0f);
    s.exp_avg_sq[g].assign(values, 0.0f);
  }
  s.grad_accum.assign(model.size(), 0.0f);
  s.denom.assign(model.size(), 0u);
  s.max_radius.assign(model.size(), 0.0f);
  return s;
}

void TrainingState::check() const {
  model.check();
  for (uint32_t g = 0; g < kParamGroupCount; ++g) {
    const size_t values = group_values(model, g).size();
    if (exp_avg[g].size() != values || exp_avg_sq[g].size() != values)
      throw std::invalid_argument(std::string("TrainingState: moments of ") + kParamGroupNames[g] + " have " +
                                  std::to_string(exp_avg[g].size()) + "/" +
                                  std::to_string(exp_avg_sq[g].size()) + " values, expected " +
                                  std::to_string(values));
  }
  if (grad_accum.size() != size() || denom.size() != size() || max_radius.size() != size())
    throw std::invalid_argument("TrainingState: statistics sizes disagree with the model's " +
                                std::to_string(size()) + " Gaussians");
}

}  // namespace litgs::kernels
