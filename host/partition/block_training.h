// Training the blocks of a partition (partition_scene.h) through an executor, each block one `litgs-engine
// train BLOCK --out BLOCK/train` of the same binary:
// - local: the blocks one after another, or K at a time;
// - slurm: one `sbatch --wait` job array (`--array=0-(N-1)`), whose task $SLURM_ARRAY_TASK_ID trains the
//   N-th pending block; the cluster's own scheduler, never a home-made one.
// A block whose model is already there is skipped, so a rerun continues where a failed one stopped. A failed
// block does not stop the others; it is reported by its name and its log once they have run.
#pragma once

#include <filesystem>
#include <functional>
#include <string>
#include <vector>

namespace litgs::host::partition {

enum class Executor { kLocal, kSlurm };
Executor executor_from(const std::string& name);  // "local" | "slurm"; std::invalid_argument otherwise

// Per array task; empty: not asked of the scheduler (its defaults apply). Defaults are set by
// default_slurm_resources from the largest block.
struct SlurmResources {
  std::string gres = "gpu:1";  // one GPU per task: the engine uses one device
  std::string mem;             // e.g. "16G"
  std::string time;            // e.g. "04:00:00"
  std::string partition;
  std::vector<std::string> extra;  // more #SBATCH lines' arguments, as given
};

struct BlockTrainingOptions {
  Executor executor = Executor::kLocal;
  size_t parallel = 1;                  // local: blocks at a time
  std::vector<std::string> train_args;  // added to every block's `train`
  SlurmResources slurm;
  std::string sbatch = "sbatch";  // found on PATH unless a path
};

struct BlockOutcome;
using BlockProgress = std::function<void(const BlockOutcome&)>;  // called as each block ends

struct BlockOutcome {
  std::string name;
  std::string state;  // "trained", "done before", "failed"
  std::filesystem::path log;
  double seconds = 0;  // its training's wall time; 0 under slurm (the scheduler's accounting has it)
  std::string tail;    // a failed block's last output
};

struct BlockTrainingReport {
  std::vector<BlockOutcome> blocks;
  std::filesystem::path script;  // slurm: the array script it submitted
  double seconds = 0;
};

// Memory per array task from the largest block: its frames at full size as float32 (targets and renders,
// four copies) plus 4 GiB for the process and the map, rounded up to GiB.
SlurmResources default_slurm_resources(const std::filesystem::path& dir, SlurmResources given);

// The job array script for `pending` blocks of partition DIR (pure: for tests and for the user to read).
std::string slurm_array_script(const std::filesystem::path& dir, const std::filesystem::path& engine,
                               const std::vector<std::string>& pending, const BlockTrainingOptions& options);

// Trains every block of DIR without a model. std::runtime_error naming the executor when sbatch cannot be
// found, and, after all blocks ran, naming each failed block and its log.
BlockTrainingReport train_blocks(const std::filesystem::path& dir, const std::filesystem::path& engine,
                                 const BlockTrainingOptions& options, const BlockProgress& progress = {});

}  // namespace litgs::host::partition
