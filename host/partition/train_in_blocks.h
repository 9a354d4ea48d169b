// `litgs-engine train-blocks SCENE --out DIR`: partition the scene (DIR/partition), train its blocks through
// an executor (block_training.h), merge them into DIR/point_cloud.ply, and write DIR/metrics.json. What
// `run` does when `train.blocks` is not 1. A rerun keeps the partition and the blocks already trained.
#pragma once

#include <filesystem>

#include "host/partition/block_plan.h"
#include "host/partition/block_training.h"
#include "host/partition/partition_scene.h"

namespace litgs::host::partition {

struct TrainInBlocksReport {
  PartitionReport partition;
  BlockTrainingReport training;
  MergeReport merge;
  double seconds = 0;
};

// std::runtime_error naming the problem (partition_scene, train_blocks, merge_blocks); what was written
// before the failure is kept for the rerun.
TrainInBlocksReport train_in_blocks(const std::filesystem::path& scene, const std::filesystem::path& out,
                                    const PartitionOptions& partition, const BlockTrainingOptions& training,
                                    const std::filesystem::path& engine, const BlockProgress& progress = {});

}  // namespace litgs::host::partition
