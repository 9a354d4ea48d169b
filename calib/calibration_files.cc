#include "calib/calibration_files.h"

#include <iomanip>

#include "io/atomic_file.h"
#include "io/scene_yaml.h"

namespace litgs::calib {

nlohmann::json intrinsics_json(const IntrinsicsResult& r) {
  const io::CameraIntrinsics& k = r.camera;
  nlohmann::json views = nlohmann::json::array();
  for (const auto& v : r.views)
    views.push_back({{"image", v.name},
                     {"used", v.used},
                     {"rms_px", v.rms_px >= 0 ? nlohmann::json(v.rms_px) : nlohmann::json(nullptr)},
                     {"note", v.note}});
  nlohmann::json stddev = nullptr;
  if (!r.stddev.empty()) {
    stddev = {{"fx", r.stddev[0]},
              {"fy", r.stddev[1]},
              {"cx", r.stddev[2]},
              {"cy", r.stddev[3]},
              {"distortion", std::vector<double>(r.stddev.begin() + 4, r.stddev.end())}};
  }
  return {{"model", k.model == io::CameraModel::kPinhole ? "pinhole" : "equidistant"},
          {"width", k.width},
          {"height", k.height},
          {"fx", k.fx},
          {"fy", k.fy},
          {"cx", k.cx},
          {"cy", k.cy},
          {"distortion", k.distortion},
          {"rms_px", r.rms_px},
          {"views_used", r.views_used},
          {"coverage", r.coverage},
          {"stddev", stddev},
          {"views", views},
          {"notes", r.notes}};
}

std::filesystem::path write_intrinsics_files(const std::filesystem::path& path, const IntrinsicsResult& r) {
  const io::CameraIntrinsics& k = r.camera;
  io::write_file_atomic(path, [&](std::ostream& out) {
    out << "# Thermal intrinsics from litgs-engine calib intrinsics (" << r.views_used << " views, RMS "
        << r.rms_px << " px): the camera block of scene.yaml (docs/scene-format.md)\n"
        << io::camera_yaml_block(k);
  });
  std::filesystem::path info = path.parent_path() / (path.stem().string() + "_camera_info.yaml");
  io::write_file_atomic(info, [&](std::ostream& out) {
    out << std::setprecision(17) << "image_width: " << k.width << "\nimage_height: " << k.height
        << "\ncamera_name: thermal\ncamera_matrix:\n  rows: 3\n  cols: 3\n  data: [" << k.fx << ", 0, "
        << k.cx << ", 0, " << k.fy << ", " << k.cy << ", 0, 0, 1]\n"
        << "distortion_model: " << (k.model == io::CameraModel::kPinhole ? "plumb_bob" : "equidistant")
        << "\ndistortion_coefficients:\n  rows: 1\n  cols: " << k.distortion.size() << "\n  data: [";
    for (size_t i = 0; i < k.distortion.size(); ++i) out << (i ? ", " : "") << k.distortion[i];
    out << "]\nrectification_matrix:\n  rows: 3\n  cols: 3\n  data: [1, 0, 0, 0, 1, 0, 0, 0, 1]\n"
        << "projection_matrix:\n  rows: 3\n  cols: 4\n  data: [" << k.fx << ", 0, " << k.cx << ", 0, 0, "
        << k.fy << ", " << k.cy << ", 0, 0, 0, 1, 0]\n";
  });
  return info;
}

namespace {

nlohmann::json matrix_rows(const Eigen::Matrix4d& T) {
  nlohmann::json rows = nlohmann::json::array();
  for (int r = 0; r < 4; ++r) rows.push_back({T(r, 0), T(r, 1), T(r, 2), T(r, 3)});
  return rows;
}

nlohmann::json optional_number(double v) {
  return v >= 0 ? nlohmann::json(v) : nlohmann::json(nullptr);
}

}  // namespace

nlohmann::json extrinsic_json(const ExtrinsicResult& r) {
  nlohmann::json views = nlohmann::json::array();
  for (const auto& v : r.views)
    views.push_back({{"view", v.name},
                     {"used", v.used},
                     {"rms_px", optional_number(v.rms_px)},
                     {"rms_m", optional_number(v.rms_m)},
                     {"note", v.note}});
  return {{"T_cam_lidar", matrix_rows(r.T_cam_lidar.matrix())},
          {"rms_px", r.rms_px},
          {"rms_m", r.rms_m},
          {"rotation_sd_deg", r.rotation_sd_deg},
          {"translation_sd_m", r.translation_sd_m},
          {"views_used", r.views_used},
          {"views", views}};
}

void write_extrinsic_yaml(const std::filesystem::path& path, const ExtrinsicResult& r) {
  const Eigen::Matrix4d T = r.T_cam_lidar.matrix();
  io::write_file_atomic(path, [&](std::ostream& out) {
    out << "# Thermal-to-LiDAR extrinsic from litgs-engine calib extrinsic (" << r.views_used
        << " views, RMS " << r.rms_px << " px, " << r.rms_m
        << " m): scene.yaml's T_cam_lidar (docs/scene-format.md)\n"
        << "T_cam_lidar:  # maps LiDAR points into the camera frame\n"
        << std::setprecision(17);
    for (int row = 0; row < 4; ++row)
      out << "  - [" << T(row, 0) << ", " << T(row, 1) << ", " << T(row, 2) << ", " << T(row, 3) << "]\n";
  });
}

void write_extrinsic_into_scene(const std::filesystem::path& scene_yaml, const ExtrinsicResult& r) {
  io::SceneConfig scene = io::read_scene_yaml(scene_yaml);
  scene.T_cam_lidar = r.T_cam_lidar.matrix();
  io::write_scene_yaml(scene_yaml, scene);
}

}  // namespace litgs::calib
