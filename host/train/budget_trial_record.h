// One finished training of the budget search (a budget and a fold), kept beside it as trial.json so that a
// search cut short (Ctrl-C, kill -9) continues under `train --resume` without training it again. The key
// says what the training was: its options, its data (host::run_options_json) and what it started from
// (host::start_fingerprint); a record whose key differs is not reused.
#pragma once

#include <cstdint>
#include <filesystem>
#include <nlohmann/json.hpp>
#include <optional>
#include <vector>

namespace litgs::host {

struct FinishedTrial {
  double psnr_db = 0;  // on the fold's validation views
  double ssim = 0;
  std::vector<double> view_psnr_db;  // each validation view's, in the views' order
  uint32_t gaussians = 0;            // the model's size at the end
  double wall_s = 0;
};

// DIR/trial.json, written atomically once the training has finished.
void write_finished_trial(const std::filesystem::path& dir, const nlohmann::json& key,
                          const FinishedTrial& t);

// The record in DIR when there is one with this key; nothing when it is missing, unreadable or made with
// another key (then the training runs again and overwrites it).
std::optional<FinishedTrial> read_finished_trial(const std::filesystem::path& dir, const nlohmann::json& key);

}  // namespace litgs::host
