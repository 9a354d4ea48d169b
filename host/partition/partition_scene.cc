#include "host/partition/partition_scene.h"

#include <chrono>
#include <cmath>
#include <fstream>
#include <limits>
#include <nlohmann/json.hpp>
#include <optional>
#include <stdexcept>

#include "host/frontend/intensity.h"
#include "host/run/content_hash.h"
#include "host/train/output_frame.h"
#include "host/train/training_data.h"
#include "io/atomic_file.h"
#include "io/export_scene.h"
#include "io/gaussian_ply.h"
#include "io/pcd.h"
#include "io/scene.h"
#include "io/scene_yaml.h"

namespace litgs::host::partition {
namespace fs = std::filesystem;
using nlohmann::json;

namespace {

constexpr double kInf = std::numeric_limits<double>::infinity();

json edge_json(double e) {
  return std::isfinite(e) ? json(e) : json(nullptr);
}
double edge_from(const json& j, double infinite) {
  return j.is_null() ? infinite : j.get<double>();
}

json cell_json(const CoreCell& c) {
  return json::array({edge_json(c.x0), edge_json(c.x1), edge_json(c.y0), edge_json(c.y1)});
}
CoreCell cell_from(const json& j) {
  return {edge_from(j.at(0), -kInf), edge_from(j.at(1), kInf), edge_from(j.at(2), -kInf),
          edge_from(j.at(3), kInf)};
}

// What identifies the source scene: its configuration and its trajectory.
std::string scene_fingerprint(const fs::path& scene) {
  return run::hash_text(run::hash_path(scene / "scene.yaml") + run::hash_path(scene / "poses.txt"));
}

io::PointCloud subset(const io::PointCloud& cloud, const std::vector<size_t>& keep) {
  io::PointCloud out;
  for (size_t i : keep) {
    out.positions.push_back(cloud.positions[i]);
    if (!cloud.intensity.empty()) out.intensity.push_back(cloud.intensity[i]);
    if (!cloud.normals.empty()) out.normals.push_back(cloud.normals[i]);
  }
  for (const auto& f : cloud.extra) {
    io::ScalarField g{f.name, {}};
    for (size_t i : keep) g.values.push_back(f.values[i]);
    out.extra.push_back(std::move(g));
  }
  return out;
}

void link_or_copy(const fs::path& from, const fs::path& to) {
  std::error_code ec;
  fs::remove(to, ec);
  fs::create_hard_link(from, to, ec);
  if (ec) fs::copy_file(from, to, fs::copy_options::overwrite_existing);
}

// The whole scene's intensity window, as training would take it (host/train/training_data.h), for every
// block: models trained apart then share one intensity scale. 8-bit frames are not stretched.
io::SceneConfig block_config(const fs::path& scene_dir, const io::Scene& scene) {
  io::SceneConfig c = scene.config;
  if (c.intensity_window) return c;
  frontend::Histogram histogram = frontend::empty_histogram();
  for (size_t i = 0; i < scene.frames.size(); ++i) {
    const io::Image img = io::load_frame(scene_dir, scene, i);
    frontend::add_to_histogram(histogram, img.data, static_cast<size_t>(img.channels));
  }
  // Training's own rule; recorded for 8-bit frames too (training reads it when it maps by percentiles).
  const frontend::Stretch s = percentile_window(c, histogram, TrainingDataOptions{});
  c.intensity_window = std::make_pair(s.low, s.high);
  return c;
}

json plan_json(const BlockPlan& plan, const std::vector<size_t>& view_frame) {
  json blocks = json::array();
  for (const Block& b : plan.blocks) {
    json frames = json::array();
    for (size_t v : b.views) frames.push_back(view_frame[v]);
    blocks.push_back({{"name", b.name},
                      {"column", b.column},
                      {"row", b.row},
                      {"core", cell_json(b.core)},
                      {"expanded", cell_json(b.expanded)},
                      {"views", b.views.size()},
                      {"views_by_position", b.views_by_position},
                      {"views_by_visibility", b.views_by_visibility},
                      {"views_seeing_core", b.views_seeing_core},
                      {"map_points", b.map_points.size()},
                      {"core_map_points", b.core_map_points},
                      {"frames", frames}});
  }
  return {{"columns", plan.columns},
          {"rows", plan.rows},
          {"overlap_m", plan.overlap_m},
          {"why", plan.why},
          {"blocks", blocks}};
}

void write_block(const fs::path& scene_dir, const io::Scene& scene, const io::SceneConfig& config,
                 const Block& b, const std::vector<size_t>& view_frame, const fs::path& dir) {
  fs::create_directories(dir / "thermal");
  fs::create_directories(dir / "lidar");
  link_or_copy(scene_dir / "poses.txt", dir / "poses.txt");
  for (size_t v : b.views) {
    const fs::path& image = scene.frames[view_frame[v]].image;
    link_or_copy(scene_dir / image, dir / image);
  }
  io::PcdWriteOptions pcd;
  pcd.double_positions = true;
  io::write_pcd(dir / "lidar/map.pcd", subset(*scene.map, b.map_points), pcd);
  if (fs::exists(scene_dir / "gt/poses.txt")) {
    fs::create_directories(dir / "gt");
    link_or_copy(scene_dir / "gt/poses.txt", dir / "gt/poses.txt");
    if (fs::exists(scene_dir / "gt/planes.txt"))
      link_or_copy(scene_dir / "gt/planes.txt", dir / "gt/planes.txt");
  }
  io::write_file_atomic(dir / "block.json", [&](std::ostream& os) {
    os << json{{"name", b.name}, {"core", cell_json(b.core)}, {"expanded", cell_json(b.expanded)}}.dump(2)
       << "\n";
  });
  // scene.yaml last: a block folder without it is not a scene, so a failure above leaves no half scene.
  io::write_scene_yaml(dir / "scene.yaml", config);
}

}  // namespace

PartitionReport partition_scene(const fs::path& scene_dir, const fs::path& out, const PartitionOptions& o) {
  const auto t0 = std::chrono::steady_clock::now();
  io::SceneReadOptions read;
  read.check_images = false;
  const io::Scene scene = io::read_scene(scene_dir, read);
  if (!scene.map || scene.map->size() == 0)
    throw std::runtime_error("partition: " + scene_dir.string() +
                             " has no LiDAR map (lidar/map.pcd): blocks are cut by its points");
  const std::string fingerprint = scene_fingerprint(scene_dir);
  const fs::path manifest = out / kPartitionFile;
  json old;
  if (fs::exists(manifest)) {
    old = json::parse(std::ifstream(manifest), nullptr, false);
    if (old.is_discarded() || old.value("scene_fingerprint", "") != fingerprint)
      throw std::runtime_error("partition: " + out.string() + " holds a partition of another scene (" +
                               (old.is_discarded() ? std::string("unreadable partition.json")
                                                   : old.value("scene", std::string("?"))) +
                               "): use another folder");
  }

  PartitionReport r;
  std::vector<PlanView> views;
  std::vector<size_t> view_frame;
  const auto poses = io::camera_poses_at_frames(scene);
  const io::CameraIntrinsics& K = scene.config.camera;
  for (size_t f = 0; f < poses.size(); ++f) {
    if (!poses[f]) continue;
    if (o.scene_holdout_every > 0 && f % o.scene_holdout_every == 0) {
      ++r.heldout_frames;
      continue;
    }
    PlanView v;
    v.T_world_cam.matrix() = *poses[f];
    v.fx = K.fx, v.fy = K.fy, v.cx = K.cx, v.cy = K.cy, v.width = K.width, v.height = K.height;
    views.push_back(v);
    view_frame.push_back(f);
  }
  r.plan = plan_blocks(views, scene.map->positions, o);
  check_blocks(r.plan, views.size());
  json j = plan_json(r.plan, view_frame);
  // The same scene cut another way: the blocks' trainings there belong to other cells.
  if (old.is_object() && old.value("blocks", json()) != j.at("blocks"))
    throw std::runtime_error("partition: " + out.string() +
                             " holds another partition of this scene (other blocks, cells or frames): its "
                             "blocks' trainings would be merged with the wrong cells; use another folder");
  const io::SceneConfig config = block_config(scene_dir, scene);
  fs::create_directories(out / kBlocksDir);
  for (const Block& b : r.plan.blocks)
    write_block(scene_dir, scene, config, b, view_frame, out / kBlocksDir / b.name);
  j["scene"] = fs::weakly_canonical(scene_dir).string();
  j["scene_fingerprint"] = fingerprint;
  j["frames"] = scene.frames.size();
  j["map_points"] = scene.map->size();
  j["heldout_every"] = o.scene_holdout_every;
  j["heldout_frames"] = r.heldout_frames;
  if (config.intensity_window)
    j["intensity_window"] = {config.intensity_window->first, config.intensity_window->second};
  io::write_file_atomic(manifest, [&](std::ostream& os) { os << j.dump(2) << "\n"; });
  r.out = out;
  r.frames = scene.frames.size();
  r.map_points = scene.map->size();
  r.seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  return r;
}

PartitionManifest read_partition(const fs::path& dir, const std::string& who) {
  const fs::path manifest = dir / kPartitionFile;
  std::ifstream in(manifest);
  if (!in) throw std::runtime_error(who + ": " + manifest.string() + " not found: partition first");
  const json plan = json::parse(in, nullptr, false);
  if (plan.is_discarded() || !plan.contains("blocks"))
    throw std::runtime_error(who + ": " + manifest.string() + " is not a partition (does not parse)");
  PartitionManifest m;
  m.overlap_m = plan.value("overlap_m", 0.0);
  for (const auto& b : plan.at("blocks"))
    m.blocks.push_back({b.at("name"), cell_from(b.at("core")), b.value("views", size_t{0})});
  return m;
}

MergeReport merge_blocks(const fs::path& dir, const fs::path& out_ply, const std::string& model_dir) {
  std::vector<std::pair<std::string, CoreCell>> cores;
  for (const PartitionBlock& b : read_partition(dir, "merge").blocks) cores.emplace_back(b.name, b.core);

  MergeReport r;
  r.out = out_ply;
  kernels::GaussianModel merged;
  std::optional<ModelFrame> frame;
  std::vector<std::string> comments;
  for (size_t k = 0; k < cores.size(); ++k) {
    const fs::path ply = dir / kBlocksDir / cores[k].first / model_dir / "point_cloud.ply";
    if (!fs::exists(ply))
      throw std::runtime_error("merge: " + cores[k].first + " has no model (" + ply.string() +
                               " not found): train it first");
    const kernels::GaussianModel m = io::read_gaussian_ply(ply);
    const ModelFrame f = read_model_frame(ply);
    if (!frame) {
      frame = f;
      comments = model_frame_comments(f);
      merged.channels = m.channels;
      merged.sh_degree = m.sh_degree;
    } else if (f.world_offset_m != frame->world_offset_m || m.channels != merged.channels ||
               m.sh_degree != merged.sh_degree) {
      throw std::runtime_error("merge: " + ply.string() +
                               " disagrees with the first block's model in its frame, channels or degree");
    }
    // Core cells are in the scene frame: scene = model + model offset - scene offset.
    const Eigen::Vector3d to_scene = f.world_offset_m - f.scene_world_offset_m.value_or(f.world_offset_m);
    MergedBlock mb{cores[k].first, m.size(), 0};
    const size_t K = m.sh_coeffs() * m.channels;
    for (size_t i = 0; i < m.size(); ++i) {
      const double x = m.means[3 * i] + to_scene.x(), y = m.means[3 * i + 1] + to_scene.y();
      size_t homes = 0;
      for (const auto& [name, core] : cores) homes += core.contains(x, y);
      if (homes != 1)
        throw std::runtime_error("merge: a Gaussian of " + cores[k].first + " lies in " +
                                 std::to_string(homes) + " core cells: the partition's cells do not tile");
      if (!cores[k].second.contains(x, y)) continue;
      ++mb.kept;
      merged.means.insert(merged.means.end(), m.means.begin() + 3 * i, m.means.begin() + 3 * i + 3);
      merged.log_scales.insert(merged.log_scales.end(), m.log_scales.begin() + 3 * i,
                               m.log_scales.begin() + 3 * i + 3);
      merged.quats.insert(merged.quats.end(), m.quats.begin() + 4 * i, m.quats.begin() + 4 * i + 4);
      merged.opacity_logits.push_back(m.opacity_logits[i]);
      merged.sh.insert(merged.sh.end(), m.sh.begin() + K * i, m.sh.begin() + K * (i + 1));
    }
    r.gaussians += mb.kept;
    r.blocks.push_back(mb);
  }
  merged.check();
  io::write_gaussian_ply(out_ply, merged, comments);
  return r;
}

}  // namespace litgs::host::partition
