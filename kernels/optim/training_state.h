// The host image of a model in training: parameters, Adam moments and densification statistics
// (checkpoints, tests, and the CPU references). No Vulkan.
#pragma once

#include <array>
#include <cstdint>
#include <vector>

#include "kernels/splat/splat_types.h"

namespace litgs::kernels {

// Parameter groups, in the order of the moment arrays and of the Adam non-finite counters.
enum ParamGroup : uint32_t { kMeans = 0, kLogScales, kQuats, kOpacityLogits, kSh, kParamGroupCount };
inline constexpr const char* kParamGroupNames[kParamGroupCount] = {"means", "log_scales", "quats",
                                                                   "opacity_logits", "sh"};

// The model's array of a group.
std::vector<float>& group_values(GaussianModel& model, uint32_t group);
const std::vector<float>& group_values(const GaussianModel& model, uint32_t group);

struct TrainingState {
  GaussianModel model;
  std::array<std::vector<float>, kParamGroupCount> exp_avg;     // per group, the shape of the model's array
  std::array<std::vector<float>, kParamGroupCount> exp_avg_sq;  // per group
  std::vector<float> grad_accum;  // [N] sum of screen-gradient norms (see DensifyOptions::grad_threshold)
  std::vector<uint32_t> denom;    // [N] views in which the Gaussian was visible
  std::vector<float> max_radius;  // [N] largest screen radius seen, pixels

  // A state for `model` with zero moments and statistics.
  static TrainingState fresh(const GaussianModel& model);
  size_t size() const { return model.size(); }
  // Throws std::invalid_argument naming the array whose size disagrees with the model.
  void check() const;
};

}  // namespace litgs::kernels
