// `litgs-engine export colmap|tum --scene SCENE --out ...`: a scene directory into the formats other tools
// read (COLMAP, 3DGS trainers, evo). CPU only: no Vulkan device is created.
#include <CLI/CLI.hpp>
#include <iostream>
#include <memory>

#include "io/export_scene.h"
#include "tools/commands.h"

namespace litgs::tools {

void add_export_command(CLI::App& app) {
  CLI::App* exp = app.add_subcommand("export", "Write a scene directory in another tool's format");
  exp->require_subcommand(1);

  auto c = std::make_shared<io::ColmapExportOptions>();
  CLI::App* colmap = exp->add_subcommand("colmap", "COLMAP model + images (OUT/sparse/0, OUT/images)");
  colmap->add_option("--scene", c->scene, "Scene directory")->required()->check(CLI::ExistingDirectory);
  colmap->add_option("--out", c->out, "Folder to write")->required();
  colmap->add_flag("--binary", c->binary, "Write .bin model files (default: .txt)");
  colmap->add_flag("--recentred", c->recentred, "Keep the scene's recentred coordinates (default: original)");
  colmap->add_option("--max-points", c->max_points, "At most this many points3D (0: none)")
      ->capture_default_str();
  colmap->callback([c] {
    const io::ColmapExportReport r = io::export_colmap(*c);
    std::cout << "export colmap: " << r.images << " images, " << r.points << " points3D into "
              << c->out.string() << "\n";
    for (const auto& note : r.notes) std::cout << "  note: " << note << "\n";
  });

  auto t = std::make_shared<io::TumExportOptions>();
  CLI::App* tum = exp->add_subcommand("tum", "TUM trajectory (t x y z qx qy qz qw), e.g. for evo");
  tum->add_option("--scene", t->scene, "Scene directory")->required()->check(CLI::ExistingDirectory);
  tum->add_option("--out", t->out, "TUM file to write")->required();
  tum->add_flag("--camera", t->camera, "Camera poses at the frame timestamps (default: poses.txt as stored)");
  tum->add_flag("--gt", t->ground_truth, "Export gt/poses.txt instead of poses.txt");
  tum->add_flag("--recentred", t->recentred, "Keep the scene's recentred coordinates (default: original)");
  tum->callback([t] {
    const size_t n = io::export_tum(*t);
    std::cout << "export tum: " << n << " poses into " << t->out.string() << "\n";
  });
}

}  // namespace litgs::tools
