#include "host/partition/seam_metrics.h"

#include <cmath>
#include <limits>
#include <stdexcept>

#include "host/partition/block_plan.h"
#include "host/partition/partition_scene.h"

namespace litgs::host::partition {
namespace fs = std::filesystem;
using nlohmann::json;

namespace {

constexpr double kInf = std::numeric_limits<double>::infinity();

struct Accumulator {
  double sum_sq = 0;
  size_t n = 0;
  void add(double e) { sum_sq += e * e, ++n; }
  RegionPsnr finish(const std::string& name) const {
    const double mse = n ? sum_sq / static_cast<double>(n) : std::nan("");
    return {name, n, n == 0 ? std::nan("") : mse == 0 ? kInf : -10.0 * std::log10(mse)};
  }
};

// Distance from (x, y) inside `c` to its nearest bounded edge (a border with another block).
double to_border(const CoreCell& c, double x, double y) {
  double d = kInf;
  for (const double e : {c.x0, c.x1})
    if (std::isfinite(e)) d = std::min(d, std::abs(x - e));
  for (const double e : {c.y0, c.y1})
    if (std::isfinite(e)) d = std::min(d, std::abs(y - e));
  return d;
}

json psnr_json(const RegionPsnr& r) {
  return {{"name", r.name},
          {"pixels", r.pixels},
          {"psnr_db", std::isfinite(r.psnr_db) ? json(r.psnr_db) : json(nullptr)}};
}

}  // namespace

SeamMetrics seam_metrics(const fs::path& dir, const std::vector<ViewImages>& views,
                         const std::vector<kernels::SplatCamera>& cameras, const SeamOptions& o) {
  if (views.size() != cameras.size())
    throw std::invalid_argument("seam metrics: " + std::to_string(views.size()) + " views but " +
                                std::to_string(cameras.size()) + " cameras");
  const PartitionManifest plan = read_partition(dir, "seam metrics");
  std::vector<std::string> names;
  std::vector<CoreCell> cores;
  for (const PartitionBlock& b : plan.blocks) names.push_back(b.name), cores.push_back(b.core);

  SeamMetrics m;
  m.seam_width_m = o.seam_width_m >= 0 ? o.seam_width_m : 0.5 * plan.overlap_m;
  std::vector<Accumulator> per_block(cores.size());
  Accumulator seams, interior;
  for (size_t k = 0; k < views.size(); ++k) {
    const ViewImages& v = views[k];
    const kernels::SplatCamera& c = cameras[k];
    const size_t n = static_cast<size_t>(v.width) * v.height;
    if (v.render.size() != n || v.target.size() != n || v.depth_m.size() != n || v.alpha.size() != n ||
        c.width != v.width || c.height != v.height)
      throw std::invalid_argument("seam metrics: view " + v.name + " and its camera disagree in size");
    for (uint32_t j = 0; j < v.height; ++j)
      for (uint32_t i = 0; i < v.width; ++i) {
        const size_t p = static_cast<size_t>(j) * v.width + i;
        if (!(v.alpha[p] >= o.min_alpha) || !(v.depth_m[p] > 0)) {
          ++m.unplaced;
          continue;
        }
        // Pixel centres at (i + 0.5, j + 0.5), the rasterizer's convention; depth is the camera z.
        const double z = v.depth_m[p];
        const glm::dvec3 cam((i + 0.5 - c.cx) / c.fx * z, (j + 0.5 - c.cy) / c.fy * z, z);
        const glm::dvec3 world = glm::transpose(c.R_cam_world) * (cam - c.t_cam_world);
        const double error = double{v.render[p]} - v.target[p];
        for (size_t b = 0; b < cores.size(); ++b) {
          if (!cores[b].contains(world.x, world.y)) continue;
          per_block[b].add(error);
          (to_border(cores[b], world.x, world.y) < m.seam_width_m ? seams : interior).add(error);
          break;
        }
      }
  }
  for (size_t b = 0; b < cores.size(); ++b) m.blocks.push_back(per_block[b].finish(names[b]));
  m.seams = seams.finish("seams");
  m.interior = interior.finish("interior");
  return m;
}

json to_json(const SeamMetrics& m) {
  json blocks = json::array();
  for (const auto& b : m.blocks) blocks.push_back(psnr_json(b));
  return {{"seam_width_m", m.seam_width_m},
          {"blocks", blocks},
          {"seams", psnr_json(m.seams)},
          {"interior", psnr_json(m.interior)},
          {"unplaced_pixels", m.unplaced}};
}

}  // namespace litgs::host::partition
