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

}  // namespace litgs::calib
