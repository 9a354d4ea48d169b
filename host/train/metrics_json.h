// metrics.json of a training run: timing, model size, held-out quality, every evaluation, counters.
#pragma once

#include <filesystem>
#include <nlohmann/json.hpp>

#include "host/train/train_options.h"
#include "host/train/trainer.h"
#include "host/train/training_data.h"

namespace litgs::host {

nlohmann::json metrics_json(const TrainReport& report, const TrainingData& data, const TrainOptions& options);
// Writes metrics_json(...) to `path` atomically (io::IoError naming the file on failure).
void write_metrics_json(const std::filesystem::path& path, const TrainReport& report,
                        const TrainingData& data, const TrainOptions& options);

}  // namespace litgs::host
