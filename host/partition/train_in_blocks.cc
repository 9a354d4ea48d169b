#include "host/partition/train_in_blocks.h"

#include <chrono>
#include <fstream>
#include <nlohmann/json.hpp>

#include "io/atomic_file.h"

namespace litgs::host::partition {
namespace fs = std::filesystem;

namespace {

// A block's own training metrics (train's metrics.json), or null where it has none.
nlohmann::json block_training_metric(const fs::path& block, const char* key) {
  std::ifstream in(block / kBlockTrainDir / "metrics.json");
  const nlohmann::json j = nlohmann::json::parse(in, nullptr, false);
  return in && j.is_object() && j.contains(key) ? j[key] : nlohmann::json(nullptr);
}

}  // namespace

TrainInBlocksReport train_in_blocks(const fs::path& scene, const fs::path& out, const PartitionOptions& po,
                                    const BlockTrainingOptions& to, const fs::path& engine,
                                    const BlockProgress& progress) {
  const auto t0 = std::chrono::steady_clock::now();
  TrainInBlocksReport r;
  const fs::path dir = out / "partition";
  r.partition = partition_scene(scene, dir, po);
  r.training = train_blocks(dir, engine, to, progress);
  r.merge = merge_blocks(dir, out / "point_cloud.ply");
  r.seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();

  nlohmann::json blocks = nlohmann::json::array();
  for (size_t k = 0; k < r.training.blocks.size(); ++k) {
    const BlockOutcome& b = r.training.blocks[k];
    const Block& planned = r.partition.plan.blocks.at(k);
    blocks.push_back(
        {{"name", b.name},
         {"state", b.state},
         {"seconds", b.seconds},  // this run's: 0 for a block a rerun kept
         // The block's training's own wall time, which a rerun keeps.
         {"train_seconds", block_training_metric(dir / kBlocksDir / b.name, "wall_s")},
         {"views", planned.views.size()},
         {"map_points", planned.map_points.size()},
         {"gaussians", r.merge.blocks.at(k).gaussians},
         {"kept", r.merge.blocks.at(k).kept},
         {"peak_device_bytes", block_training_metric(dir / kBlocksDir / b.name, "peak_device_bytes")},
         {"log", b.log.string()},
         // Its loss curve, relative to `out` (the run report draws one per block).
         {"trace",
          (dir / kBlocksDir / b.name / kBlockTrainDir / kBlockTrace).lexically_relative(out).string()}});
  }
  const nlohmann::json metrics = {{"gaussians", r.merge.gaussians},
                                  {"wall_s", r.seconds},
                                  {"executor", to.executor == Executor::kLocal ? "local" : "slurm"},
                                  {"columns", r.partition.plan.columns},
                                  {"rows", r.partition.plan.rows},
                                  {"blocks", blocks}};
  // One training's loss curve has no meaning here (each block has its own: blocks[].trace); the run
  // report reads an empty one.
  io::write_file_atomic(out / "trace.jsonl", [](std::ostream&) {});
  io::write_file_atomic(out / "metrics.json", [&](std::ostream& os) { os << metrics.dump(2) << "\n"; });
  return r;
}

}  // namespace litgs::host::partition
