// `litgs-engine partition SCENE --out DIR [--blocks auto|CxR] [--overlap M] [--max-gaussians-per-block N]`
// and `litgs-engine merge DIR --out point_cloud.ply`: host/partition/partition_scene.h.
#include <CLI/CLI.hpp>
#include <iomanip>
#include <iostream>
#include <memory>
#include <stdexcept>

#include "engine/context.h"
#include "host/partition/partition_option_names.h"
#include "host/partition/partition_scene.h"
#include "host/partition/train_in_blocks.h"
#include "tools/commands.h"

namespace litgs::tools {
namespace {

// "auto", "N" or "CxR".
void parse_blocks(const std::string& text, host::partition::PartitionOptions& o) {
  if (text == "auto") return;
  if (!text.empty() && text.find_first_not_of("0123456789") == std::string::npos) {
    o.blocks = std::stoul(text);
    if (o.blocks == 0) throw CLI::ValidationError("--blocks", "the block count must be >= 1");
    return;
  }
  const size_t x = text.find('x');
  size_t used_c = 0, used_r = 0;
  try {
    if (x == std::string::npos) throw std::invalid_argument(text);
    o.columns = std::stoul(text.substr(0, x), &used_c);
    o.rows = std::stoul(text.substr(x + 1), &used_r);
  } catch (const std::exception&) {
    throw CLI::ValidationError("--blocks", "expected auto, N or COLUMNSxROWS (e.g. 3x1), got '" + text + "'");
  }
  if (used_c != x || used_r != text.size() - x - 1 || o.columns == 0 || o.rows == 0)
    throw CLI::ValidationError("--blocks",
                               "expected auto or COLUMNSxROWS with both >= 1, got '" + text + "'");
}

void print_report(const host::partition::PartitionReport& r) {
  std::cout << "partition: " << r.plan.blocks.size() << " blocks (" << r.plan.columns << "x" << r.plan.rows
            << ", " << r.plan.why << "), overlap " << std::fixed << std::setprecision(2) << r.plan.overlap_m
            << " m, from " << r.frames << " frames (" << r.heldout_frames << " held out of every block) and "
            << r.map_points << " map points in " << r.seconds << " s; written to " << r.out.string() << "\n";
  for (const auto& b : r.plan.blocks)
    std::cout << "  " << b.name << ": " << b.views.size() << " views (" << b.views_by_position
              << " by position, " << b.views_by_visibility << " by visibility, " << b.views_seeing_core
              << " see the core), " << b.map_points.size() << " map points (" << b.core_map_points
              << " in the core)\n";
}

// The options partition and train-blocks share.
void add_partition_options(CLI::App* c, std::string& blocks, host::partition::PartitionOptions& o) {
  c->add_option(host::partition_option::kBlocks.flag, blocks,
                "auto (from the budget), N (laid out along the cameras' extent), or COLUMNSxROWS along the "
                "scene's x and y")
      ->capture_default_str();
  c->add_option("--overlap", o.overlap_m,
                "Metres each core cell grows by (default: 30 % of a cell's larger side)");
  c->add_option("--max-gaussians-per-block", o.max_gaussians_per_block,
                "auto: the block count keeps each block under this (default: half of what one storage "
                "buffer of the device holds at SH degree 3)");
  c->add_option("--gaussians", o.scene_gaussians,
                "auto: the whole scene's budget (default: the map's points)");
  c->add_option("--holdout-every", o.scene_holdout_every,
                "The scene's frames i % N == 0 (eval's held-out views) go to no block (0: none)")
      ->capture_default_str();
  c->add_option("--visibility-share", o.visibility_share,
                "A view outside a block joins it when this share of the map points it sees lie in the core")
      ->capture_default_str();
}

// auto without a per-block limit: half of what one storage buffer of the device holds at SH degree 3.
void resolve_auto(const std::string& blocks, host::partition::PartitionOptions& o) {
  parse_blocks(blocks, o);
  if (o.columns == 0 && o.blocks == 0 && o.max_gaussians_per_block == 0) {
    engine::Context context;
    o.max_gaussians_per_block =
        host::partition::gaussians_per_buffer(context.info().max_storage_buffer_range, 3, 1) / 2;
  }
}

}  // namespace

void add_partition_command(CLI::App& app) {
  CLI::App* c = app.add_subcommand(
      "partition", "Split a scene into block scenes on the ground plane, for training block by block");
  auto scene = std::make_shared<std::filesystem::path>();
  auto out = std::make_shared<std::filesystem::path>();
  auto blocks = std::make_shared<std::string>("auto");
  auto o = std::make_shared<host::partition::PartitionOptions>();
  c->add_option("scene", *scene, "Scene directory (needs lidar/map.pcd)")
      ->required()
      ->check(CLI::ExistingDirectory);
  c->add_option("--out", *out, "Partition folder: partition.json and blocks/<name>/")->required();
  add_partition_options(c, *blocks, *o);
  c->callback([scene, out, blocks, o] {
    resolve_auto(*blocks, *o);
    print_report(host::partition::partition_scene(*scene, *out, *o));
  });

  CLI::App* m = app.add_subcommand("merge", "Join the blocks' trained models into one 3DGS PLY by core cell");
  auto dir = std::make_shared<std::filesystem::path>();
  auto ply = std::make_shared<std::filesystem::path>();
  auto model_dir = std::make_shared<std::string>(host::partition::kBlockTrainDir);
  m->add_option("dir", *dir, "Partition folder (partition.json)")->required()->check(CLI::ExistingDirectory);
  m->add_option("--out", *ply, "The merged point_cloud.ply")->required();
  m->add_option("--model-dir", *model_dir, "Each block's training output, inside its scene folder")
      ->capture_default_str();
  m->callback([dir, ply, model_dir] {
    const auto r = host::partition::merge_blocks(*dir, *ply, *model_dir);
    for (const auto& b : r.blocks)
      std::cout << "  " << b.name << ": kept " << b.kept << " of " << b.gaussians
                << " Gaussians (centres in its core cell)\n";
    std::cout << "merge: " << r.gaussians << " Gaussians from " << r.blocks.size() << " blocks, written to "
              << r.out.string() << "\n";
  });

  CLI::App* t = app.add_subcommand(
      "train-blocks", "Partition a scene, train its blocks (locally or as a Slurm job array) and merge them");
  auto tscene = std::make_shared<std::filesystem::path>();
  auto tout = std::make_shared<std::filesystem::path>();
  auto tblocks = std::make_shared<std::string>("auto");
  auto tpo = std::make_shared<host::partition::PartitionOptions>();
  auto tto = std::make_shared<host::partition::BlockTrainingOptions>();
  auto executor = std::make_shared<std::string>("local");
  t->add_option("scene", *tscene, "Scene directory (needs lidar/map.pcd)")
      ->required()
      ->check(CLI::ExistingDirectory);
  t->add_option("--out", *tout, "Output folder: point_cloud.ply, metrics.json, partition/")->required();
  add_partition_options(t, *tblocks, *tpo);
  namespace P = host::partition_option;
  t->add_option(P::kExecutor.flag, *executor, P::kExecutor.help)
      ->check(CLI::IsMember({"local", "slurm"}))
      ->capture_default_str();
  t->add_option(P::kJobs.flag, tto->parallel, P::kJobs.help)->capture_default_str();
  t->add_option(P::kGres.flag, tto->slurm.gres, P::kGres.help)->capture_default_str();
  t->add_option(P::kMem.flag, tto->slurm.mem, P::kMem.help);
  t->add_option(P::kTime.flag, tto->slurm.time, P::kTime.help);
  t->add_option(P::kSlurmPartition.flag, tto->slurm.partition, P::kSlurmPartition.help);
  t->add_option("--sbatch-arg", tto->slurm.extra, "slurm: one more #SBATCH line's arguments (repeatable)");
  t->add_option("--sbatch", tto->sbatch, "slurm: the sbatch program")->capture_default_str();
  t->add_option("--train-arg", tto->train_args, "One more argument for every block's train (repeatable)");
  t->callback([tscene, tout, tblocks, tpo, tto, executor] {
    resolve_auto(*tblocks, *tpo);
    tto->executor = host::partition::executor_from(*executor);
    const auto r = host::partition::train_in_blocks(
        *tscene, *tout, *tpo, *tto, this_executable(), [](const host::partition::BlockOutcome& b) {
          std::cout << "  " << b.name << ": " << b.state;
          if (b.state == "trained" && b.seconds > 0)
            std::cout << " in " << std::fixed << std::setprecision(1) << b.seconds << " s";
          std::cout << " (log " << b.log.string() << ")\n" << std::flush;
        });
    print_report(r.partition);
    std::cout << "train-blocks: " << r.merge.gaussians << " Gaussians from " << r.merge.blocks.size()
              << " blocks in " << std::fixed << std::setprecision(1) << r.seconds << " s; wrote "
              << (*tout / "point_cloud.ply").string() << " and metrics.json\n";
  });
}

}  // namespace litgs::tools
