// `litgs-engine map SCENE [--voxel V] [--out FILE] [--force] [--no-deskew]`: the LiDAR map of a scene from
// its scans and poses (host/lidar_map/map_builder.h). CPU only.
#include <CLI/CLI.hpp>
#include <iomanip>
#include <iostream>
#include <memory>

#include "host/lidar_map/map_builder.h"
#include "host/lidar_map/map_option_names.h"
#include "tools/commands.h"

namespace litgs::tools {

void print_lidar_map_report(const host::LidarMapReport& r, const std::string& where) {
  std::cout << std::fixed << std::setprecision(2) << "map: " << r.scans << " scans (" << r.scans_deskewed
            << " deskewed), " << r.input_points << " points -> " << r.map_points << " map points ("
            << r.planar_points << " planar) in " << r.seconds << " s, peak memory " << r.peak_rss_mb
            << " MB; written to " << where << "\n";
  if (r.scans_heldout > 0)
    std::cout << "map: " << r.scans_heldout << " scans held out of the map (" << r.heldout_points
              << " points, lidar/heldout.pcd beside it): eval measures geometry against them\n";
  for (const auto& note : r.notes) std::cout << "  note: " << note << "\n";
}

void add_map_command(CLI::App& app) {
  CLI::App* c = app.add_subcommand("map", "Build lidar/map.pcd from the scene's LiDAR scans and poses");
  auto scene = std::make_shared<std::filesystem::path>();
  auto out = std::make_shared<std::filesystem::path>();
  auto force = std::make_shared<bool>(false);
  auto o = std::make_shared<host::LidarMapOptions>();
  c->add_option("scene", *scene, "Scene directory")->required()->check(CLI::ExistingDirectory);
  c->add_option(host::map_option::kVoxel.flag, o->voxel_m, host::map_option::kVoxel.help)
      ->capture_default_str();
  c->add_option("--out", *out, "Write the map here instead of lidar/map.pcd (scene.yaml untouched)");
  c->add_flag("--force", *force, "Replace an existing lidar/map.pcd");
  c->add_flag(host::map_option::kDeskew.flag, o->deskew, host::map_option::kDeskew.help);
  c->add_option(
       "--holdout-every", o->holdout_every,
       "Leave scans 0, N, 2N, ... out of the map, for eval's geometry and refine's scan check (0: none)")
      ->capture_default_str();
  c->callback([scene, out, force, o] {
    const host::LidarMapReport r = host::write_scene_lidar_map(*scene, *o, *out, *force);
    print_lidar_map_report(r, out->empty() ? (*scene / "lidar/map.pcd").string() : out->string());
  });
}

}  // namespace litgs::tools
