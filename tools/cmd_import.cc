// `litgs-engine import metashape|colmap|livo2|bag ... --out SCENE`: other tools' outputs into a scene
// directory (docs/scene-format.md). CPU only: no Vulkan device is created.
#include <CLI/CLI.hpp>
#include <iostream>
#include <memory>

#include "host/lidar_map/map_builder.h"
#include "io/import_bag.h"
#include "io/import_colmap.h"
#include "io/import_livo2.h"
#include "io/import_metashape.h"
#include "tools/commands.h"

namespace litgs::tools {
namespace {

void print_offset(const Eigen::Vector3d& v) {
  std::cout << "world offset [" << v.x() << ", " << v.y() << ", " << v.z() << "] m\n";
}

void add_import_colmap(CLI::App* import) {
  auto o = std::make_shared<io::ColmapImportOptions>();
  auto offset = std::make_shared<std::vector<double>>();
  CLI::App* c = import->add_subcommand("colmap", "COLMAP sparse model (text or binary) plus its images");
  c->add_option("--model", o->model, "Model folder: cameras/images/points3D as .bin or .txt")
      ->required()
      ->check(CLI::ExistingDirectory);
  c->add_option("--images", o->images, "Folder the image names are relative to")
      ->required()
      ->check(CLI::ExistingDirectory);
  c->add_option("--out", o->out, "Scene directory to write")->required();
  c->add_option("--world-offset", *offset,
                "Recentring offset X Y Z in metres (default: mean camera centre, rounded to metres)")
      ->expected(3);
  c->add_option("--image-format", o->image_extension, "Extension of the written frames: .png or .tiff")
      ->capture_default_str();
  c->add_flag("!--no-anchors", o->points_as_anchors, "Do not write points3D as anchors.txt");
  c->add_option("--anchor-min-error", o->anchor_min_error_px,
                "Floor of the reprojection error (px) behind an anchor's covariance")
      ->capture_default_str();
  c->callback([o, offset] {
    if (!offset->empty()) o->world_offset_m = Eigen::Vector3d((*offset)[0], (*offset)[1], (*offset)[2]);
    const io::ColmapImportReport r = io::import_colmap(*o);
    std::cout << "import colmap: " << r.frames << " frames, " << r.anchors << " anchors into "
              << o->out.string() << ", ";
    print_offset(r.world_offset_m);
    for (const auto& note : r.notes) std::cout << "  note: " << note << "\n";
  });
}

void add_import_livo2(CLI::App* import) {
  auto o = std::make_shared<io::Livo2ImportOptions>();
  auto offset = std::make_shared<std::vector<double>>();
  CLI::App* c = import->add_subcommand("livo2", "FAST-LIVO2 Log/ folder plus its configuration YAML(s)");
  c->add_option("--log", o->log, "FAST-LIVO2's Log folder (result/, pcd/, image/)")
      ->required()
      ->check(CLI::ExistingDirectory);
  c->add_option("--config", o->config,
                "YAML file(s) holding cam_* keys, extrinsic_R/T and Rcl/Pcl (main and camera config)")
      ->required()
      ->check(CLI::ExistingFile);
  c->add_option("--out", o->out, "Scene directory to write")->required();
  c->add_option("--trajectory", o->trajectory, "TUM file of IMU poses (default: the one .txt in LOG/result)")
      ->check(CLI::ExistingFile);
  c->add_option("--map", o->map,
                "PCD map (default: LOG/pcd/all_downsampled_points.pcd, all_raw_points.pcd, or all merged)")
      ->check(CLI::ExistingFile);
  c->add_option("--world-offset", *offset, "Recentring offset X Y Z in metres (default 0)")->expected(3);
  c->add_option("--image-format", o->image_extension, "Extension of the written frames: .png or .tiff")
      ->capture_default_str();
  c->callback([o, offset] {
    if (!offset->empty()) o->world_offset_m = Eigen::Vector3d((*offset)[0], (*offset)[1], (*offset)[2]);
    const io::Livo2ImportReport r = io::import_livo2(*o);
    std::cout << "import livo2: " << r.frames << " frames (" << r.skipped_no_pose << " without a pose), "
              << r.map_points << " map points into " << o->out.string() << "\n";
    for (const auto& note : r.notes) std::cout << "  note: " << note << "\n";
  });
}

void add_import_bag(CLI::App* import) {
  auto o = std::make_shared<io::BagImportOptions>();
  auto frame = std::make_shared<std::string>("imu");
  CLI::App* c = import->add_subcommand(
      "bag", "ROS 1 bag (thermal images, LiDAR, IMU, odometry) plus M2DGR calibration");
  c->add_option("--bag", o->bag, "ROS 1 bag")->required()->check(CLI::ExistingFile);
  c->add_option("--calib", o->calib, "M2DGR calibration_results.txt")->required()->check(CLI::ExistingFile);
  c->add_option("--calib-block", o->calib_block, "Camera block of the calibration")->capture_default_str();
  c->add_option(
       "--imu-block", o->imu_block,
       "IMU block of the calibration for T_imu_lidar: auto (by the IMU topic), none (identity), or a "
       "block name such as 'Xsens IMU'")
      ->capture_default_str();
  c->add_option("--out", o->out, "Scene directory to write")->required();
  c->add_option("--thermal-topic", o->topics.thermal, "sensor_msgs/Image topic")->capture_default_str();
  c->add_option("--lidar-topic", o->topics.lidar, "sensor_msgs/PointCloud2 topic")->capture_default_str();
  c->add_option("--imu-topic", o->topics.imu, "sensor_msgs/Imu topic")->capture_default_str();
  c->add_option("--odom-topic", o->topics.odom, "nav_msgs/Odometry topic for poses.txt (default: none)");
  c->add_option("--poses", o->poses, "TUM trajectory for poses.txt when the bag has no odometry")
      ->check(CLI::ExistingFile);
  c->add_option("--poses-frame", *frame, "Frame of the poses: imu or camera")
      ->check(CLI::IsMember({"imu", "camera"}))
      ->capture_default_str();
  c->add_option("--gt", o->ground_truth, "TUM ground truth for gt/poses.txt")->check(CLI::ExistingFile);
  c->add_flag("!--no-scans", o->scans, "Do not write the LiDAR scans");
  c->add_flag("--reindex", o->reindex,
              "Read a bag cut short (no index, or one past its end) without its index, keeping every "
              "complete chunk, as rosbag reindex does; the notes say what was lost");
  c->add_option("--image-format", o->image_extension, "Extension of the written frames: .png or .tiff")
      ->capture_default_str();
  auto map = std::make_shared<bool>(true);
  auto voxel = std::make_shared<double>(host::LidarMapOptions{}.voxel_m);
  c->add_flag("!--no-map", *map,
              "Do not build lidar/map.pcd from the scans (litgs-engine map does it later)");
  c->add_option("--map-voxel", *voxel, "Voxel edge of the map in metres")->capture_default_str();
  c->callback([o, frame, map, voxel] {
    o->poses_frame = *frame == "camera" ? io::PoseFrame::kCamera : io::PoseFrame::kImu;
    const io::BagImportReport r = io::import_bag(*o);
    std::cout << "import bag: " << r.frames << " frames, " << r.scans << " scans, " << r.imu
              << " IMU samples, " << r.poses << " poses into " << o->out.string() << "\n";
    for (const auto& note : r.notes) std::cout << "  note: " << note << "\n";
    if (*map && r.scans > 0) {
      host::LidarMapOptions mo;
      mo.voxel_m = *voxel;
      print_lidar_map_report(host::write_scene_lidar_map(o->out, mo), (o->out / "lidar/map.pcd").string());
    }
  });
}

}  // namespace

void add_import_command(CLI::App& app) {
  CLI::App* import = app.add_subcommand("import", "Convert another tool's output into a scene directory");
  import->require_subcommand(1);

  auto o = std::make_shared<io::MetashapeImportOptions>();
  auto offset = std::make_shared<std::vector<double>>();
  CLI::App* ms = import->add_subcommand("metashape", "Agisoft Metashape camera XML plus its images");
  ms->add_option("--xml", o->xml, "Camera XML (File > Export > Cameras)")
      ->required()
      ->check(CLI::ExistingFile);
  ms->add_option("--images", o->images, "Folder of <camera label>.tiff|.tif|.png")
      ->required()
      ->check(CLI::ExistingDirectory);
  ms->add_option("--out", o->out, "Scene directory to write")->required();
  ms->add_option("--calibration", o->calibration, "Stand-alone calibration XML replacing the sensor's own")
      ->check(CLI::ExistingFile);
  ms->add_option("--world-offset", *offset,
                 "Recentring offset X Y Z in metres (default: mean camera centre, rounded to metres)")
      ->expected(3);
  ms->add_option("--image-format", o->image_extension, "Extension of the written frames: .png or .tiff")
      ->capture_default_str();
  ms->callback([o, offset] {
    if (!offset->empty()) o->world_offset_m = Eigen::Vector3d((*offset)[0], (*offset)[1], (*offset)[2]);
    const io::MetashapeImportReport r = io::import_metashape(*o);
    std::cout << "import metashape: " << r.frames << " frames into " << o->out.string() << " ("
              << r.skipped_unaligned << " unaligned cameras skipped), world offset [" << r.world_offset_m.x()
              << ", " << r.world_offset_m.y() << ", " << r.world_offset_m.z() << "] m\n";
    for (const auto& note : r.notes) std::cout << "  note: " << note << "\n";
  });
  add_import_colmap(import);
  add_import_livo2(import);
  add_import_bag(import);
}

}  // namespace litgs::tools
