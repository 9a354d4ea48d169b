// The options of a training run and the identity of its training data, as checkpoints store them, and the
// check that decides whether `train --resume` may continue a checkpoint with this run's options.
//
// May differ on resume (each difference is reported as a note):
//   iterations        to extend (or shorten) the run; not below the checkpoint's iteration. From the resume
//   on,
//                     the means' learning-rate decay and the refinement window (densify_until clipped to the
//                     run) follow the new total, so an extended run is not the run that had started with it.
//   eval_every, checkpoint_every, progress_every   reporting cadence only.
//   recentred_output  the frame point_cloud.ply is written in (the checkpoint keeps the scene frame).
// Every other option of TrainOptions and of TrainingDataOptions, and the training data itself (resolution,
// views and hold-out split, cameras, target images, the scene's world_offset_m), must be the checkpoint's.
#pragma once

#include <cstdint>
#include <filesystem>
#include <nlohmann/json.hpp>
#include <string>
#include <vector>

#include "host/train/train_options.h"
#include "host/train/training_data.h"

namespace litgs::host {

struct PlanarMap;

// {"train": {...TrainOptions but resume}, "data_options": {...TrainingDataOptions}, "data": {identity}}.
// Float options are stored as their shortest decimal form, so that messages read "0.0002", not
// "0.000199999994947575".
nlohmann::json run_options_json(const TrainOptions& options, const TrainingData& data);

// A fingerprint (FNV-1a, 16 hex digits) of what a training starts from besides its options and data: the
// initial model and the LiDAR planes of its geometric term (none: nullptr). The budget search keeps it with
// each finished trial, so that a resumed search reuses a trial only if it would train the same.
std::string start_fingerprint(const kernels::GaussianModel& initial, const PlanarMap* planes);

// Compares the options stored in `checkpoint` (written after `checkpoint_iteration` iterations) with this
// run's. Returns one note per allowed difference (and per option the checkpoint did not record, assumed
// unchanged); throws std::invalid_argument "CHECKPOINT: train --resume refused: ..." that names every other
// difference with the checkpoint's and this run's value (and the CLI flag where there is one).
std::vector<std::string> check_resume_options(const std::filesystem::path& checkpoint,
                                              uint32_t checkpoint_iteration, const nlohmann::json& stored,
                                              const nlohmann::json& now);

}  // namespace litgs::host
