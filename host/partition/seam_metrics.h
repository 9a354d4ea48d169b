// The held-out PSNR of a merged model per block and along the seams: each pixel's rendered surface point
// (expected depth, where the render is opaque enough) is placed on the ground plane, in the core cell of its
// block, and counted as seam when it lies within a width of a cell border shared with another block. Where
// blocks were trained apart, the seams are where a merged model can fail.
#pragma once

#include <filesystem>
#include <string>
#include <vector>

#include "host/eval/evaluate_model.h"
#include "kernels/splat/splat_types.h"

namespace litgs::host::partition {

struct SeamOptions {
  double seam_width_m = -1;  // < 0: half the partition's overlap
  double min_alpha = 0.5;    // pixels whose render is more transparent than this have no surface to place
};

struct RegionPsnr {
  std::string name;
  size_t pixels = 0;
  double psnr_db = 0;  // NaN without pixels; +inf where the render equals the target
};

struct SeamMetrics {
  double seam_width_m = 0;
  std::vector<RegionPsnr> blocks;  // in partition.json's order
  RegionPsnr seams{"seams"}, interior{"interior"};
  size_t unplaced = 0;  // pixels without a surface (alpha below min_alpha)
};

// views[k] rendered through cameras[k]. std::runtime_error naming partition.json when it cannot be read;
// std::invalid_argument when views and cameras disagree in count or size.
SeamMetrics seam_metrics(const std::filesystem::path& partition_dir, const std::vector<ViewImages>& views,
                         const std::vector<kernels::SplatCamera>& cameras, const SeamOptions& options = {});

nlohmann::json to_json(const SeamMetrics& m);

}  // namespace litgs::host::partition
