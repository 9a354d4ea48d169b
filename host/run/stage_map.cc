// map: the LiDAR map from the scene's scans and poses (`litgs-engine map`), in DIR/map/scene. By default
// only where the scene has scans and no map; map.build: always rebuilds an imported map from the scans.
#include <stdexcept>

#include "host/lidar_map/map_option_names.h"
#include "host/run/stage.h"

namespace litgs::host::run {
namespace {

namespace fs = std::filesystem;

bool has_scans(const fs::path& scene) {
  const fs::path scans = scene / "lidar" / "scans";
  return fs::is_directory(scans) && !fs::is_empty(scans);
}

StagePlan plan(const StageContext& c) {
  const RunConfig::Map& o = c.config.map;
  const fs::path scene = c.scene();
  StagePlan p;
  p.options = section_json(c.config, "map");
  if (o.build != "auto" && o.build != "always" && o.build != "never")
    throw std::invalid_argument("map.build: '" + o.build + "' is not auto, always or never");
  const bool has_map = fs::exists(scene / "lidar" / "map.pcd");
  if (o.build == "never") {
    p.skip_reason = "map.build is never";
  } else if (!has_scans(scene)) {
    p.skip_reason = "scene has no scans (lidar/scans/)";
  } else if (has_map && o.build == "auto") {
    p.skip_reason = "scene has a LiDAR map already (map.build: always rebuilds it from the scans)";
  }
  if (!p.skip_reason.empty()) return p;
  // The map is rewritten (with --force), and read_scene wants it while scene.yaml says it is there.
  std::vector<std::string> flags = {"--force"};
  for (const std::string& f : option_flags(p.options, {map_option::kVoxel, map_option::kDeskew}))
    flags.push_back(f);
  plan_on_scene_copy(c, "map", SceneCopy{scene, {"scene.yaml", "lidar/map.pcd"}, {}}, flags, o.extra_args, p);
  return p;
}

nlohmann::json result(const StageContext& c) {
  return {{"scene", (c.stage_dir("map") / "scene").string()}, {"metrics", nlohmann::json::object()}};
}

}  // namespace

Stage map_stage() {
  return {"map", "LiDAR map from the scans and poses", plan, result};
}

}  // namespace litgs::host::run
