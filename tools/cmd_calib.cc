// `litgs-engine calib intrinsics ...`: thermal intrinsics from an asymmetric circle grid; `calib extrinsic
// ...`: the thermal-to-LiDAR extrinsic from a holed board (calib/). Parses, calls calib/, prints and writes.
#include <CLI/CLI.hpp>
#include <algorithm>
#include <cstdio>
#include <filesystem>
#include <iostream>
#include <memory>

#include "calib/calibration_files.h"
#include "calib/circle_grid.h"
#include "calib/extrinsic_views.h"
#include "calib/holed_board.h"
#include "calib/intrinsics.h"
#include "io/image.h"
#include "io/scene_yaml.h"
#include "tools/commands.h"

namespace litgs::tools {
namespace {

namespace fs = std::filesystem;

struct IntrinsicsCli {
  fs::path images, out;
  std::string grid = "4x11", polarity = "auto", model = "pinhole";
  double spacing_m = 0;
  bool clahe = false, json = false;
};

void run_intrinsics(const IntrinsicsCli& o) {
  const calib::CircleGrid grid = calib::parse_circle_grid(o.grid, o.spacing_m);
  const calib::Polarity polarity = calib::parse_polarity(o.polarity);
  std::vector<fs::path> files;
  for (const auto& e : fs::directory_iterator(o.images)) {
    const std::string ext = e.path().extension().string();
    if (e.is_regular_file() && (ext == ".png" || ext == ".tif" || ext == ".tiff")) files.push_back(e.path());
  }
  std::sort(files.begin(), files.end());
  if (files.empty()) throw std::invalid_argument(o.images.string() + ": no .png or .tif images");
  std::vector<calib::CalibrationView> views;
  for (const fs::path& f : files) {
    const io::Image image = io::read_image(f);  // names the file when it is unreadable
    calib::CalibrationView v{f.filename().string(), image.width, image.height, {}};
    v.detection = calib::detect_circle_grid(image, grid, polarity, o.clahe);
    if (!o.json)
      std::cout << "  " << v.name << ": "
                << (v.detection.found ? "grid found (" + v.detection.polarity + " circles)"
                                      : v.detection.why_not)
                << "\n";
    views.push_back(std::move(v));
  }
  calib::IntrinsicsOptions options;
  options.model = o.model == "equidistant" ? io::CameraModel::kEquidistant : io::CameraModel::kPinhole;
  const calib::IntrinsicsResult r = calib::calibrate_intrinsics(views, grid, options);
  const fs::path info = calib::write_intrinsics_files(o.out, r);
  if (o.json) {
    std::cout << calib::intrinsics_json(r).dump(2) << "\n";
    return;
  }
  char line[256];
  std::snprintf(line, sizeof line,
                "calib intrinsics: %zu of %zu views used, RMS %.3f px, %.0f %% of the image covered\n",
                r.views_used, views.size(), r.rms_px, 100 * r.coverage);
  std::cout << line;
  const auto param = [&](const char* name, double value, size_t k) {
    std::snprintf(line, sizeof line, "  %-3s %.5g", name, value);
    std::cout << line;
    if (k < r.stddev.size()) {
      std::snprintf(line, sizeof line, " +- %.2g", r.stddev[k]);
      std::cout << line;
    }
    std::cout << "\n";
  };
  param("fx", r.camera.fx, 0);
  param("fy", r.camera.fy, 1);
  param("cx", r.camera.cx, 2);
  param("cy", r.camera.cy, 3);
  // OpenCV's order: k1 k2 p1 p2 (k3) for the pinhole model, k1..k4 for the equidistant one.
  const bool fisheye = r.camera.model == io::CameraModel::kEquidistant;
  const char* const pinhole_names[] = {"k1", "k2", "p1", "p2", "k3"};
  const char* const fisheye_names[] = {"k1", "k2", "k3", "k4"};
  for (size_t k = 0; k < r.camera.distortion.size() && k < (fisheye ? 4u : 5u); ++k)
    param(fisheye ? fisheye_names[k] : pinhole_names[k], r.camera.distortion[k], 4 + k);
  if (r.stddev.empty())
    std::cout << "  (cv::fisheye gives no standard deviations for the equidistant model)\n";
  for (const auto& v : r.views)
    if (!v.used && v.rms_px >= 0) std::cout << "  left out " << v.name << ": " << v.note << "\n";
  for (const auto& n : r.notes) std::cout << "  note: " << n << "\n";
  std::cout << "  wrote " << o.out.string() << " and " << info.string() << "\n";
}

struct ExtrinsicCli {
  fs::path images, scans, board, intrinsics, scene, out;
  double beam_divergence_mrad = 3;
  bool json = false;
};

void run_extrinsic(const ExtrinsicCli& o) {
  if (o.intrinsics.empty() && o.scene.empty())
    throw std::invalid_argument(
        "calib extrinsic: the camera's intrinsics are needed: --intrinsics camera.yaml "
        "(as calib intrinsics writes it) or --scene scene.yaml");
  const io::CameraIntrinsics K = io::read_camera_yaml(o.intrinsics.empty() ? o.scene : o.intrinsics);
  const calib::HoledBoard board = calib::read_holed_board(o.board);
  calib::BoardInScanOptions scan_options;
  scan_options.beam_divergence_rad = o.beam_divergence_mrad / 1000;
  const auto print_view = [&](const calib::ExtrinsicView& v) {
    if (o.json) return;
    std::cout << "  " << v.name << ": image " << (v.image.found ? "board found" : v.image.why_not)
              << "; scan "
              << (v.scan.found ? "board found (" + std::to_string(v.scan.board_points) + " returns)"
                               : v.scan.why_not)
              << "\n";
  };
  const std::vector<calib::ExtrinsicView> views =
      calib::find_boards(o.images, o.scans, K, board, scan_options, print_view);
  const calib::ExtrinsicResult r = calib::solve_extrinsic(views, K, board, {});
  calib::write_extrinsic_yaml(o.out, r);
  if (!o.scene.empty()) calib::write_extrinsic_into_scene(o.scene, r);
  if (o.json) {
    std::cout << calib::extrinsic_json(r).dump(2) << "\n";
    return;
  }
  char line[256];
  std::snprintf(
      line, sizeof line,
      "calib extrinsic: %zu of %zu views used, RMS %.3f px, %.4f m (rotation +- %.3g deg, translation "
      "+- %.2g m)\n",
      r.views_used, views.size(), r.rms_px, r.rms_m, r.rotation_sd_deg, r.translation_sd_m);
  std::cout << line << "  T_cam_lidar:\n";
  const Eigen::Matrix4d T = r.T_cam_lidar.matrix();
  for (int row = 0; row < 4; ++row) {
    std::snprintf(line, sizeof line, "    %10.6f %10.6f %10.6f %10.5f\n", T(row, 0), T(row, 1), T(row, 2),
                  T(row, 3));
    std::cout << line;
  }
  for (const auto& v : r.views)
    if (!v.used && v.rms_px >= 0) std::cout << "  left out " << v.name << ": " << v.note << "\n";
  std::cout << "  wrote " << o.out.string()
            << (o.scene.empty() ? "" : " and T_cam_lidar into " + o.scene.string()) << "\n";
}

}  // namespace

void add_calib_command(CLI::App& app) {
  CLI::App* calib = app.add_subcommand(
      "calib",
      "Calibrate the rig: thermal intrinsics from a circle grid, the LiDAR extrinsic from a holed board");
  calib->require_subcommand(1);
  auto o = std::make_shared<IntrinsicsCli>();
  CLI::App* in =
      calib->add_subcommand("intrinsics", "Thermal intrinsics from views of an asymmetric circle grid");
  in->add_option("--images", o->images, "Folder of the views (8- or 16-bit PNG or TIFF)")
      ->required()
      ->check(CLI::ExistingDirectory);
  in->add_option("--grid", o->grid, "COLSxROWS of OpenCV's asymmetric layout (4x11: 4 columns, 11 rows)")
      ->capture_default_str();
  in->add_option("--spacing", o->spacing_m,
                 "Metres between neighbouring circles of a column (S in ((2j + i mod 2) S, i S))")
      ->required();
  in->add_option("--polarity", o->polarity, "Circles hot, cold or auto (both tried)")
      ->check(CLI::IsMember({"auto", "hot", "cold"}))
      ->capture_default_str();
  in->add_option("--model", o->model, "pinhole (k1 k2 p1 p2) or equidistant (fisheye k1..k4)")
      ->check(CLI::IsMember({"pinhole", "equidistant"}))
      ->capture_default_str();
  in->add_flag("--clahe", o->clahe, "CLAHE before the detection (low-contrast boards)");
  in->add_option("--out", o->out,
                 "camera.yaml to write (scene.yaml's camera block; ROS camera_info beside it)")
      ->required();
  in->add_flag("--json", o->json, "Print the result as one JSON object");
  in->callback([o] { run_intrinsics(*o); });

  auto e = std::make_shared<ExtrinsicCli>();
  CLI::App* ex = calib->add_subcommand(
      "extrinsic", "The thermal-to-LiDAR extrinsic from views of a board with circular holes");
  ex->add_option("--images", e->images, "Folder of the thermal views (8- or 16-bit PNG or TIFF)")
      ->required()
      ->check(CLI::ExistingDirectory);
  ex->add_option("--scans", e->scans,
                 "Folder of the LiDAR scans (.pcd or .ply, LiDAR frame), named as the images")
      ->required()
      ->check(CLI::ExistingDirectory);
  ex->add_option("--board", e->board, "board.yaml: the board's size, hole radius and hole centres")
      ->required()
      ->check(CLI::ExistingFile);
  ex->add_option("--intrinsics", e->intrinsics,
                 "camera.yaml (calib intrinsics' output), else --scene's camera")
      ->check(CLI::ExistingFile);
  ex->add_option("--scene", e->scene, "A scene.yaml whose T_cam_lidar is replaced by the result")
      ->check(CLI::ExistingFile);
  ex->add_option("--beam-divergence", e->beam_divergence_mrad,
                 "The LiDAR beam's full divergence in mrad (edges seem wider by half a footprint)")
      ->capture_default_str();
  ex->add_option("--out", e->out, "extrinsic.yaml to write (scene.yaml's T_cam_lidar block)")->required();
  ex->add_flag("--json", e->json, "Print the result as one JSON object");
  ex->callback([e] { run_extrinsic(*e); });
}

}  // namespace litgs::tools
