// The options `litgs-engine train-blocks` shares with run.yaml's train section (host/option_name.h): how a
// scene larger than one device is trained in blocks. Their values live in RunConfig::Train and in
// PartitionOptions / BlockTrainingOptions.
#pragma once

#include "host/option_name.h"

namespace litgs::host::partition_option {

inline constexpr OptionName kBlocks{
    "blocks", "--blocks",
    "1 (one training of the whole scene), auto (from the budget and the device's buffer limit), N blocks, or "
    "COLUMNSxROWS along the scene's x and y (docs/cli/train-blocks.md)"};
inline constexpr OptionName kExecutor{
    "executor", "--executor", "Blocks: local (this machine) or slurm (one sbatch job array, waited for)"};
inline constexpr OptionName kJobs{"block_jobs", "--jobs", "Blocks, local: blocks trained at a time"};
inline constexpr OptionName kGres{"slurm_gres", "--gres", "Blocks, slurm: generic resources per task"};
inline constexpr OptionName kMem{"slurm_mem", "--mem",
                                 "Blocks, slurm: memory per task (empty: from the largest block)"};
inline constexpr OptionName kTime{"slurm_time", "--time",
                                  "Blocks, slurm: time limit per task (empty: the partition's)"};
inline constexpr OptionName kSlurmPartition{
    "slurm_partition", "--slurm-partition",
    "Blocks, slurm: the cluster partition (queue); empty: the default"};

}  // namespace litgs::host::partition_option
