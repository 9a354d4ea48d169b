#include "host/partition/block_plan.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <stdexcept>

namespace litgs::host::partition {
namespace {

constexpr double kInf = std::numeric_limits<double>::infinity();
// The visibility test projects at most this many map points (every k-th): enough to measure a share.
constexpr size_t kVisibilitySample = 20000;

// Boundaries splitting `values` into `parts` groups of about equal count: parts + 1 edges, the outer ones
// infinite. Equal counts of cameras give blocks of similar work.
std::vector<double> quantile_edges(std::vector<double> values, size_t parts) {
  std::sort(values.begin(), values.end());
  std::vector<double> edges{-kInf};
  for (size_t k = 1; k < parts; ++k) {
    const size_t i = std::min(values.size() - 1, k * values.size() / parts);
    // Between two neighbouring cameras, so that no camera sits on an edge.
    const double e = i == 0 ? values[0] : 0.5 * (values[i - 1] + values[i]);
    edges.push_back(std::max(e, edges.back()));
  }
  edges.push_back(kInf);
  return edges;
}

size_t interval_of(const std::vector<double>& edges, double v) {
  const auto it = std::upper_bound(edges.begin() + 1, edges.end() - 1, v);
  return static_cast<size_t>(it - edges.begin()) - 1;
}

CoreCell grow(const CoreCell& c, double by) {
  return {c.x0 - by, c.x1 + by, c.y0 - by, c.y1 + by};
}

}  // namespace

void PartitionOptions::check() const {
  if ((columns == 0) != (rows == 0))
    throw std::invalid_argument("partition: give both columns and rows (NxM), or neither (auto)");
  if (!(visibility_share > 0 && visibility_share <= 1))
    throw std::invalid_argument("partition: visibility_share must be in (0, 1]");
  if (!(max_view_depth_m > 0)) throw std::invalid_argument("partition: max_view_depth_m must be > 0");
  if (!std::isfinite(overlap_m)) throw std::invalid_argument("partition: overlap_m must be finite");
  if (columns == 0 && blocks == 0 && max_gaussians_per_block == 0)
    throw std::invalid_argument("partition: auto needs max_gaussians_per_block > 0");
}

size_t blocks_needed(size_t scene_gaussians, size_t max_gaussians_per_block) {
  if (max_gaussians_per_block == 0) return 1;
  return std::max<size_t>(1, (scene_gaussians + max_gaussians_per_block - 1) / max_gaussians_per_block);
}

size_t gaussians_per_buffer(uint64_t max_storage_buffer_range, int sh_degree, int channels) {
  const uint64_t bytes = static_cast<uint64_t>((sh_degree + 1) * (sh_degree + 1)) *
                         static_cast<uint64_t>(channels) * sizeof(float);
  return static_cast<size_t>(max_storage_buffer_range / bytes);
}

BlockPlan plan_blocks(const std::vector<PlanView>& views, const std::vector<Eigen::Vector3d>& map,
                      const PartitionOptions& o) {
  o.check();
  if (views.empty()) throw std::invalid_argument("partition: the scene has no frame with a pose");
  std::vector<Eigen::Vector3d> centres;
  for (size_t v = 0; v < views.size(); ++v) {
    centres.push_back(views[v].T_world_cam.translation());
    if (!centres.back().allFinite() || !views[v].T_world_cam.linear().allFinite())
      throw std::invalid_argument("partition: view " + std::to_string(v) + " has a non-finite pose");
  }
  for (size_t i = 0; i < map.size(); ++i)
    if (!map[i].allFinite())
      throw std::invalid_argument("partition: map point " + std::to_string(i) + " is not finite");

  BlockPlan plan;
  if (o.columns > 0) {
    plan.columns = o.columns;
    plan.rows = o.rows;
    plan.why = "as asked";
  } else {
    const size_t gaussians = o.scene_gaussians > 0 ? o.scene_gaussians : map.size();
    const size_t n = o.blocks > 0 ? o.blocks : blocks_needed(gaussians, o.max_gaussians_per_block);
    Eigen::Vector3d lo = centres[0], hi = centres[0];
    for (const auto& c : centres) lo = lo.cwiseMin(c), hi = hi.cwiseMax(c);
    const double ex = std::max(hi.x() - lo.x(), 1e-3), ey = std::max(hi.y() - lo.y(), 1e-3);
    plan.columns = std::clamp<size_t>(
        static_cast<size_t>(std::lround(std::sqrt(static_cast<double>(n) * ex / ey))), 1, n);
    plan.rows = (n + plan.columns - 1) / plan.columns;
    plan.why =
        o.blocks > 0
            ? std::to_string(n) + " blocks as asked, laid out along the cameras' extent"
            : std::to_string(gaussians) + " Gaussians at most " + std::to_string(o.max_gaussians_per_block) +
                  " per block: " + std::to_string(n) + " blocks, laid out along the cameras' extent (" +
                  std::to_string(static_cast<int>(ex)) + " x " + std::to_string(static_cast<int>(ey)) + " m)";
  }

  // Columns by the cameras' x, then rows by the y of the cameras in each column.
  std::vector<double> xs;
  for (const auto& c : centres) xs.push_back(c.x());
  const std::vector<double> column_edges = quantile_edges(xs, plan.columns);
  std::vector<std::vector<double>> row_edges(plan.columns);
  for (size_t col = 0; col < plan.columns; ++col) {
    std::vector<double> ys;
    for (const auto& c : centres)
      if (interval_of(column_edges, c.x()) == col) ys.push_back(c.y());
    if (ys.empty()) ys.push_back(0);  // a column without cameras (repeated x): rows split nothing
    row_edges[col] = quantile_edges(ys, plan.rows);
  }
  auto block_of = [&](double x, double y) {
    const size_t col = interval_of(column_edges, x);
    return col * plan.rows + interval_of(row_edges[col], y);
  };

  for (size_t col = 0; col < plan.columns; ++col)
    for (size_t row = 0; row < plan.rows; ++row) {
      Block b;
      b.column = col;
      b.row = row;
      b.name = "block-" + std::to_string(col) + "-" + std::to_string(row);
      b.core = {column_edges[col], column_edges[col + 1], row_edges[col][row], row_edges[col][row + 1]};
      plan.blocks.push_back(b);
    }
  // The overlap: a share of a typical cell's size, from the cameras' extent (outer cells are infinite). At
  // 15 % the merged street lost 1.2-1.8 dB to one whole training along the seams (a block's views see past
  // its grown cell, and its Gaussians near the core's edge stand in for what is missing there); at 30 % the
  // loss was gone (docs/experiments.md).
  if (o.overlap_m >= 0) {
    plan.overlap_m = o.overlap_m;
  } else {
    Eigen::Vector3d lo = centres[0], hi = centres[0];
    for (const auto& c : centres) lo = lo.cwiseMin(c), hi = hi.cwiseMax(c);
    plan.overlap_m = 0.30 * std::max((hi.x() - lo.x()) / static_cast<double>(plan.columns),
                                     (hi.y() - lo.y()) / static_cast<double>(plan.rows));
  }
  for (auto& b : plan.blocks) b.expanded = grow(b.core, plan.overlap_m);

  for (size_t i = 0; i < map.size(); ++i) {
    const size_t home = block_of(map[i].x(), map[i].y());
    for (size_t k = 0; k < plan.blocks.size(); ++k) {
      Block& b = plan.blocks[k];
      if (!b.expanded.contains(map[i].x(), map[i].y())) continue;
      b.map_points.push_back(i);
      b.core_map_points += k == home;
    }
  }

  // Views: by position in the expanded bounds, else by the share of what they see that lies in the core.
  const size_t step = std::max<size_t>(1, map.size() / kVisibilitySample);
  for (size_t v = 0; v < views.size(); ++v) {
    const PlanView& view = views[v];
    std::vector<size_t> seen_in(plan.blocks.size(), 0);
    size_t seen = 0;
    const Eigen::Isometry3d T_cam_world = view.T_world_cam.inverse();
    for (size_t i = 0; i < map.size(); i += step) {
      const Eigen::Vector3d p = T_cam_world * map[i];
      if (!(p.z() > 0.05 && p.z() < o.max_view_depth_m)) continue;
      const double u = view.fx * p.x() / p.z() + view.cx, w = view.fy * p.y() / p.z() + view.cy;
      if (u < 0 || w < 0 || u >= view.width || w >= view.height) continue;
      ++seen;
      ++seen_in[block_of(map[i].x(), map[i].y())];
    }
    for (size_t k = 0; k < plan.blocks.size(); ++k) {
      Block& b = plan.blocks[k];
      if (b.expanded.contains(centres[v].x(), centres[v].y())) {
        ++b.views_by_position;
      } else if (seen > 0 &&
                 static_cast<double>(seen_in[k]) >= o.visibility_share * static_cast<double>(seen)) {
        ++b.views_by_visibility;
      } else {
        continue;
      }
      b.views.push_back(v);
      b.views_seeing_core += seen_in[k] > 0;
    }
  }
  return plan;
}

void check_blocks(const BlockPlan& plan, size_t posed_views) {
  for (const Block& b : plan.blocks) {
    if (b.views.empty())
      throw std::runtime_error("partition: " + b.name + " has no views (" + std::to_string(plan.columns) +
                               "x" + std::to_string(plan.rows) + " blocks for " +
                               std::to_string(posed_views) + " posed frames): ask for fewer blocks");
    if (b.views_seeing_core == 0)
      throw std::runtime_error("partition: no view of " + b.name +
                               " sees its core cell (no LiDAR map point of it in any of its " +
                               std::to_string(b.views.size()) + " views): ask for fewer blocks");
  }
}

}  // namespace litgs::host::partition
