// `litgs-engine export colmap|tum|bag --scene SCENE --out ...`: a scene directory into the formats other
// tools read (COLMAP, 3DGS trainers, evo, ROS 1); `export splat --model M.ply --out M.splat`: a model for web
// splat viewers. CPU only: no Vulkan device is created.
#include <CLI/CLI.hpp>
#include <iostream>
#include <memory>
#include <stdexcept>
#include <string>
#include <vector>

#include "io/export_bag.h"
#include "io/export_scene.h"
#include "io/gaussian_ply.h"
#include "io/splat_export.h"
#include "tools/commands.h"

namespace litgs::tools {
namespace {

struct SplatOptions {
  std::string model, out, palette;
  std::vector<double> range;
};

void add_export_splat_command(CLI::App& exp) {
  auto o = std::make_shared<SplatOptions>();
  CLI::App* cmd = exp.add_subcommand(
      "splat",
      "A 3DGS PLY as the 32-byte .splat layout of web viewers (one-channel models: gray or a palette)");
  cmd->add_option("--model", o->model, "3DGS PLY model")->required()->check(CLI::ExistingFile);
  cmd->add_option("--out", o->out, ".splat file to write")->required();
  cmd->add_option("--palette", o->palette, "gray or ironbow: colour one-channel values over --range");
  cmd->add_option("--range", o->range, "LO HI: the values the palette spans (default 0 1)")->expected(2);
  cmd->callback([o] {
    io::SplatColouring colouring;
    if (!o->range.empty() && o->palette.empty()) throw std::invalid_argument("--range needs --palette");
    if (!o->palette.empty()) colouring.palette = io::parse_palette(o->palette);
    if (!o->range.empty()) colouring.lo = o->range[0], colouring.hi = o->range[1];
    const kernels::GaussianModel model = io::read_gaussian_ply(o->model);
    const size_t n = io::write_splat(o->out, model, colouring);
    std::cout << "export splat: " << n << " Gaussians (" << model.channels << " channel"
              << (model.channels == 1 ? "" : "s") << ", SH degree 0 kept of " << model.sh_degree << ") into "
              << o->out << "\n";
  });
}

}  // namespace

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
  tum->add_flag("--imu", t->imu, "As IMU (body) poses, converted through the scene's extrinsics if need be");
  tum->add_flag("--recentred", t->recentred, "Keep the scene's recentred coordinates (default: original)");
  tum->callback([t] {
    const size_t n = io::export_tum(*t);
    std::cout << "export tum: " << n << " poses into " << t->out.string() << "\n";
  });

  auto b = std::make_shared<io::BagExportOptions>();
  CLI::App* bag = exp->add_subcommand(
      "bag", "ROS 1 bag laid out like an M2DGR sequence: frames, scans, IMU, odometry of the IMU");
  bag->add_option("--scene", b->scene, "Scene directory")->required()->check(CLI::ExistingDirectory);
  bag->add_option("--out", b->out, ".bag file to write")->required();
  bag->add_option("--thermal-topic", b->topics.thermal, "sensor_msgs/Image")->capture_default_str();
  bag->add_option("--lidar-topic", b->topics.lidar, "sensor_msgs/PointCloud2 (empty: none)")
      ->capture_default_str();
  bag->add_option("--imu-topic", b->topics.imu, "sensor_msgs/Imu (empty: none)")->capture_default_str();
  bag->add_option("--odom-topic", b->topics.odom, "nav_msgs/Odometry of poses.txt (empty: none)")
      ->capture_default_str();
  bag->add_flag("--recentred", b->recentred, "Keep the scene's recentred coordinates (default: original)");
  bag->callback([b] {
    const io::BagExportReport r = io::export_bag(*b);
    std::cout << "export bag: " << r.frames << " frames, " << r.scans << " scans, " << r.imu
              << " IMU samples, " << r.odometry << " odometry poses into " << b->out.string() << "\n";
  });
  add_export_splat_command(*exp);
}

}  // namespace litgs::tools
