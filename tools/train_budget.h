// `train --max-gaussians N|auto`: the model's budget as given, or derived from the scene
// (host/train/scene_budget.h) and recorded in OUT/budget.json (a resumed run reads it back from there).
#pragma once

#include <Eigen/Core>
#include <cstdint>
#include <filesystem>
#include <string>
#include <vector>

#include "host/train/training_data.h"
#include "kernels/splat/splat_types.h"

namespace litgs::tools {

struct BudgetInputs {
  const host::TrainingData* data = nullptr;
  const std::vector<Eigen::Vector3d>* map_points = nullptr;  // the LiDAR map (may be empty)
  const kernels::GaussianModel* initial = nullptr;           // its means stand for the surface without a map
  bool initial_is_random = false;                            // random means say nothing about the surface
  bool resume = false;
};

// `flag` is a positive integer or "auto"; std::invalid_argument naming the problem otherwise, or when auto
// has no surface to measure (no LiDAR map and a random initialization).
uint32_t resolve_max_gaussians(const std::string& flag, const BudgetInputs& in,
                               const std::filesystem::path& out);

}  // namespace litgs::tools
