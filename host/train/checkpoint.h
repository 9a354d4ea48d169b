// Training checkpoints: everything a resumed run needs to continue exactly (parameters, Adam moments,
// densification statistics, iteration, view order and random state) and to report as one run (its options,
// evaluations, counters and earlier resumes: the run record). One binary file, written atomically; the model
// is in the scene's recentred frame, as training sees it.
//
// Format 3 ("LITGSCK3"): format 2's fields, then the level model's state (kernels/level/level_shared.h;
// empty without a level model). Format 2 ("LITGSCK2"): format 1's fields, then the run record as JSON text
// (run_record.h). Formats 1 ("LITGSCK1", before run records; its record is empty and `has_record` false)
// and 2 are still read, with an empty level state.
#pragma once

#include <cstdint>
#include <filesystem>
#include <string>
#include <vector>

#include "host/train/run_record.h"
#include "kernels/optim/training_state.h"

namespace litgs::host {

struct Checkpoint {
  uint32_t iteration = 0;            // iterations completed
  std::vector<uint32_t> view_order;  // the current epoch's order of training views
  uint32_t order_position = 0;       // next index into view_order
  std::string rng_state;             // std::mt19937 state as text (operator<<)
  kernels::TrainingState state;
  RunRecord record;
  std::vector<float> level_state;  // [frames + 1][LEVEL_STRIDE]; empty without a level model
  bool has_record = true;  // false: read from a format-1 file (no options, evaluations or counters stored)
};

void write_checkpoint(const std::filesystem::path& path, const Checkpoint& checkpoint);
// A run's checkpoint after `iteration` iterations: out_dir/checkpoints/iter_<iteration>.ckpt.
std::filesystem::path checkpoint_path(const std::filesystem::path& out_dir, uint32_t iteration);
// The checkpoint of out_dir with the highest iteration; empty if there is none.
std::filesystem::path newest_checkpoint(const std::filesystem::path& out_dir);
// io::IoError naming the file and byte on a truncated, foreign or inconsistent file (a run record that is not
// JSON of the expected shape included).
Checkpoint read_checkpoint(const std::filesystem::path& path);

}  // namespace litgs::host
