// `litgs-engine partition` and `merge`: a scene directory split into block scenes (block_plan.h) that
// `train` accepts unchanged, and the blocks' trained models joined into one 3DGS PLY by core cell.
//
//   DIR/partition.json          the plan, the source scene and its fingerprint
//   DIR/blocks/block-C-R/       a scene: scene.yaml as the source's with the whole scene's
//                               intensity_window (16-bit frames), poses.txt, thermal/ (hard links
//                               to the block's frames, copies across file systems), lidar/map.pcd (the map
//                               points inside the expanded bounds), gt/poses.txt where the source has one,
//                               block.json (the core cell)
//   DIR/blocks/block-C-R/train/ where each block's training writes (run, or the user's `train --out`)
#pragma once

#include <filesystem>
#include <string>
#include <vector>

#include "host/partition/block_plan.h"

namespace litgs::host::partition {

inline constexpr const char* kPartitionFile = "partition.json";
inline constexpr const char* kBlocksDir = "blocks";
inline constexpr const char* kBlockTrainDir = "train";     // a block's training output, inside its scene
inline constexpr const char* kBlockTrace = "trace.jsonl";  // its progress reports, inside kBlockTrainDir

struct PartitionReport {
  BlockPlan plan;
  std::filesystem::path out;
  size_t frames = 0, map_points = 0;
  size_t heldout_frames = 0;  // the scene's held-out views, in no block
  double seconds = 0;
};

// std::runtime_error naming the problem, with nothing of DIR replaced, when: the scene cannot be read, it
// has no LiDAR map, DIR holds a partition of another scene, a block has no views, or no view of a block
// sees its core cell.
PartitionReport partition_scene(const std::filesystem::path& scene, const std::filesystem::path& out,
                                const PartitionOptions& options);

// What a partition folder's partition.json says about its blocks, as merge, the executors and the seam
// metrics need it.
struct PartitionBlock {
  std::string name;
  CoreCell core;
  size_t views = 0;
};
struct PartitionManifest {
  double overlap_m = 0;
  std::vector<PartitionBlock> blocks;  // in the plan's order
};

// DIR/partition.json. std::runtime_error starting with `who` and naming the file when it is missing or is not
// a partition.
PartitionManifest read_partition(const std::filesystem::path& dir, const std::string& who);

struct MergedBlock {
  std::string name;
  size_t gaussians = 0;  // in the block's model
  size_t kept = 0;       // with their centre in the block's core cell
};

struct MergeReport {
  std::vector<MergedBlock> blocks;
  size_t gaussians = 0;  // written
  std::filesystem::path out;
};

// Reads DIR/partition.json and each block's DIR/blocks/NAME/<model_dir>/point_cloud.ply, keeps each block's
// Gaussians whose centres lie in its core cell and writes them as one PLY in the frame the blocks' models
// state (the scene's world frame). Every kept centre is checked to lie in exactly one core cell.
// std::runtime_error naming the block and file on a missing or unreadable model, models that disagree in
// channels, degree or frame, or a partition.json that does not parse.
MergeReport merge_blocks(const std::filesystem::path& dir, const std::filesystem::path& out_ply,
                         const std::string& model_dir = kBlockTrainDir);

}  // namespace litgs::host::partition
