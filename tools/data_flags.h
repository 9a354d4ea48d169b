// The training-data flags train and eval share (eval must see the views as training did).
#pragma once

#include <CLI/CLI.hpp>
#include <memory>
#include <stdexcept>
#include <string>

#include "host/train/training_data.h"

namespace litgs::tools {

struct DataFlags {
  std::string intensity = "auto";   // auto | percentile | linear
  std::string poses = "estimated";  // estimated (poses.txt) | truth (gt/poses.txt)
};

// --downscale, --holdout-every, --intensity, --poses onto `data` and `flags`.
inline void add_data_flags(CLI::App* cmd, host::TrainingDataOptions& data, DataFlags& flags) {
  cmd->add_option("--downscale", data.downscale, "Divide image size and intrinsics by this")
      ->capture_default_str();
  cmd->add_option("--holdout-every", data.holdout_every, "Hold out every Nth frame (0: none)")
      ->capture_default_str();
  cmd->add_option("--intensity", flags.intensity, "auto | percentile | linear")->capture_default_str();
  cmd->add_option("--poses", flags.poses, "estimated (poses.txt) or truth (gt/poses.txt of synthetic scenes)")
      ->capture_default_str();
}

// The string flags into `data`; std::invalid_argument naming a bad value.
inline void apply_data_flags(const DataFlags& flags, host::TrainingDataOptions& data) {
  if (flags.intensity == "percentile")
    data.mapping = host::IntensityMapping::kPercentile;
  else if (flags.intensity == "linear")
    data.mapping = host::IntensityMapping::kLinear;
  else if (flags.intensity == "auto")
    data.mapping = host::IntensityMapping::kAuto;
  else
    throw std::invalid_argument("--intensity must be auto, percentile or linear, not '" + flags.intensity +
                                "'");
  if (flags.poses != "estimated" && flags.poses != "truth")
    throw std::invalid_argument("--poses must be estimated or truth, not '" + flags.poses + "'");
  data.true_poses = flags.poses == "truth";
}

}  // namespace litgs::tools
