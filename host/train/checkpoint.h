// Training checkpoints: everything a resumed run needs to continue exactly (parameters, Adam moments,
// densification statistics, iteration, view order and random state). One binary file, written atomically.
#pragma once

#include <cstdint>
#include <filesystem>
#include <string>
#include <vector>

#include "kernels/optim/training_state.h"

namespace litgs::host {

struct Checkpoint {
  uint32_t iteration = 0;             // iterations completed
  std::vector<uint32_t> view_order;   // the current epoch's order of training views
  uint32_t order_position = 0;        // next index into view_order
  std::string rng_state;              // std::mt19937 state as text (operator<<)
  kernels::TrainingState state;
};

void write_checkpoint(const std::filesystem::path& path, const Checkpoint& checkpoint);
// A run's checkpoint after `iteration` iterations: out_dir/checkpoints/iter_<iteration>.ckpt.
std::filesystem::path checkpoint_path(const std::filesystem::path& out_dir, uint32_t iteration);
// The checkpoint of out_dir with the highest iteration; empty if there is none.
std::filesystem::path newest_checkpoint(const std::filesystem::path& out_dir);
// io::IoError naming the file and byte on a truncated, foreign or inconsistent file.
Checkpoint read_checkpoint(const std::filesystem::path& path);

}  // namespace litgs::host
