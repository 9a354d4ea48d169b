// Block partitioning of a scene too large for one device (the approach of VastGaussian and CityGaussian):
// core cells that tile the ground plane, chosen by camera positions, each expanded by an overlap and by
// visibility into the views and LiDAR map points one block trains on. Pure geometry: no files.
//
// The ground plane is the scene frame's x-y plane: LiDAR-inertial worlds are gravity-aligned with z up
// (FAST-LIVO2, LIO odometry, the synthetic scenes). Core cells are half-open and the outer ones reach to
// infinity, so every point of the plane lies in exactly one core cell: merging by core cell neither loses
// nor duplicates a Gaussian.
#pragma once

#include <Eigen/Core>
#include <Eigen/Geometry>
#include <cstddef>
#include <cstdint>
#include <string>
#include <vector>

namespace litgs::host::partition {

struct CoreCell {
  double x0, x1, y0, y1;  // [x0, x1) x [y0, y1); +-infinity at the outside of the grid
  bool contains(double x, double y) const { return x >= x0 && x < x1 && y >= y0 && y < y1; }
};

// A view for the visibility test: T_world_cam and a pinhole camera (undistorted is close enough here).
struct PlanView {
  Eigen::Isometry3d T_world_cam = Eigen::Isometry3d::Identity();
  double fx = 1, fy = 1, cx = 0, cy = 0;
  int width = 0, height = 0;
};

struct PartitionOptions {
  size_t columns = 0, rows = 0;  // the grid along x and y; 0 x 0: auto
  size_t blocks = 0;             // auto: this many blocks (0: blocks_needed from the budget)
  double overlap_m = -1;         // each core cell's border grows by this; < 0: 30 % of the cell's larger side
  // A view outside a block's expanded bounds still joins it when at least this share of the map points it
  // sees lie in the block's core cell (VastGaussian's visibility-based camera selection).
  double visibility_share = 0.25;
  double max_view_depth_m = 60;        // map points farther than this from a view do not count as seen
  size_t max_gaussians_per_block = 0;  // auto: the block count keeps each block under this
  size_t scene_gaussians = 0;          // auto: the whole scene's budget (0: the map's point count)
  // The whole scene's held-out frames (i % N == 0, as train and eval count them; 0: none) go to no block,
  // so that eval of the merged model on the whole scene scores views that no block trained on.
  size_t scene_holdout_every = 8;
  void check() const;  // std::invalid_argument naming the bad field
};

struct Block {
  std::string name;  // "block-C-R"
  size_t column = 0, row = 0;
  CoreCell core;
  CoreCell expanded;               // the core grown by the overlap (its outside edges stay infinite)
  std::vector<size_t> views;       // indices into the views given to plan_blocks, increasing
  size_t views_by_position = 0;    // of them: camera centre inside the expanded bounds
  size_t views_by_visibility = 0;  // of them: joined by the visibility test
  size_t views_seeing_core = 0;    // of them: see at least one map point of the core cell
  std::vector<size_t> map_points;  // indices of the map points inside the expanded bounds
  size_t core_map_points = 0;      // of them inside the core cell
};

struct BlockPlan {
  size_t columns = 1, rows = 1;
  double overlap_m = 0;
  std::string why;  // how the block count was chosen
  std::vector<Block> blocks;
};

// The number of blocks `auto` asks for: ceil(scene_gaussians / max_gaussians_per_block), at least 1.
size_t blocks_needed(size_t scene_gaussians, size_t max_gaussians_per_block);

// The Gaussians one storage buffer of the device holds for the largest per-Gaussian array (the SH
// coefficients: (degree + 1)^2 per channel, float32).
size_t gaussians_per_buffer(uint64_t max_storage_buffer_range, int sh_degree, int channels);

// std::invalid_argument naming the problem: no views, a non-finite camera centre or map point.
BlockPlan plan_blocks(const std::vector<PlanView>& views, const std::vector<Eigen::Vector3d>& map,
                      const PartitionOptions& options);

// std::runtime_error naming the first block that cannot be trained: one without views, or one none of whose
// views sees a map point of its core cell. `posed_views`: for the message.
void check_blocks(const BlockPlan& plan, size_t posed_views);

}  // namespace litgs::host::partition
