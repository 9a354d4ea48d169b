// `litgs-engine partition SCENE --out DIR [--blocks auto|CxR] [--overlap M] [--max-gaussians-per-block N]`
// and `litgs-engine merge DIR --out point_cloud.ply`: host/partition/partition_scene.h.
#include <CLI/CLI.hpp>
#include <iomanip>
#include <iostream>
#include <memory>
#include <stdexcept>

#include "engine/context.h"
#include "host/partition/partition_scene.h"
#include "tools/commands.h"

namespace litgs::tools {
namespace {

// "auto" or "CxR".
void parse_blocks(const std::string& text, host::partition::PartitionOptions& o) {
  if (text == "auto") return;
  const size_t x = text.find('x');
  size_t used_c = 0, used_r = 0;
  try {
    if (x == std::string::npos) throw std::invalid_argument(text);
    o.columns = std::stoul(text.substr(0, x), &used_c);
    o.rows = std::stoul(text.substr(x + 1), &used_r);
  } catch (const std::exception&) {
    throw CLI::ValidationError("--blocks", "expected auto or COLUMNSxROWS (e.g. 3x1), got '" + text + "'");
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
  c->add_option("--blocks", *blocks, "auto, or COLUMNSxROWS along the scene's x and y")
      ->capture_default_str();
  c->add_option("--overlap", o->overlap_m,
                "Metres each core cell grows by (default: 15 % of a cell's larger side)");
  c->add_option("--max-gaussians-per-block", o->max_gaussians_per_block,
                "auto: the block count keeps each block under this (default: half of what one storage "
                "buffer of the device holds at SH degree 3)");
  c->add_option("--gaussians", o->scene_gaussians,
                "auto: the whole scene's budget (default: the map's points)");
  c->add_option("--holdout-every", o->scene_holdout_every,
                "The scene's frames i % N == 0 (eval's held-out views) go to no block (0: none)")
      ->capture_default_str();
  c->add_option("--visibility-share", o->visibility_share,
                "A view outside a block joins it when this share of the map points it sees lie in the core")
      ->capture_default_str();
  c->callback([scene, out, blocks, o] {
    parse_blocks(*blocks, *o);
    if (o->columns == 0 && o->max_gaussians_per_block == 0) {
      engine::Context context;
      o->max_gaussians_per_block =
          host::partition::gaussians_per_buffer(context.info().max_storage_buffer_range, 3, 1) / 2;
    }
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
}

}  // namespace litgs::tools
