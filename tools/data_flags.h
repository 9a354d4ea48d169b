// The training-data flags train and eval share (eval must see the views as training did).
#pragma once

#include <CLI/CLI.hpp>
#include <memory>
#include <stdexcept>
#include <string>

#include "host/train/train_option_names.h"
#include "host/train/training_data.h"

namespace litgs::tools {

struct DataFlags {
  std::string intensity = "auto";   // auto | percentile | linear
  std::string poses = "estimated";  // estimated (poses.txt) | truth (gt/poses.txt)
};

// --downscale, --holdout-every, --intensity, --poses onto `data` and `flags`.
inline void add_data_flags(CLI::App* cmd, host::TrainingDataOptions& data, DataFlags& flags) {
  namespace T = host::train_option;
  cmd->add_option(T::kDownscale.flag, data.downscale, T::kDownscale.help)->capture_default_str();
  cmd->add_option(T::kHoldoutEvery.flag, data.holdout_every, T::kHoldoutEvery.help)->capture_default_str();
  cmd->add_option(T::kIntensity.flag, flags.intensity, T::kIntensity.help)->capture_default_str();
  cmd->add_option(T::kPoses.flag, flags.poses, T::kPoses.help)->capture_default_str();
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
