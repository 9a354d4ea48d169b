#include "io/scene_yaml.h"

#include <yaml-cpp/yaml.h>

#include <set>
#include <sstream>

#include "io/atomic_file.h"
#include "io/error.h"
#include "io/text.h"

namespace litgs::io {
namespace {

std::string check_rigid(const Eigen::Matrix4d& T) {
  if (!T.allFinite()) return "non-finite entries";
  if (T.row(3) != Eigen::RowVector4d(0, 0, 0, 1)) return "last row is not 0 0 0 1";
  const Eigen::Matrix3d R = T.topLeftCorner<3, 3>();
  if ((R.transpose() * R - Eigen::Matrix3d::Identity()).norm() > 1e-6) return "rotation is not orthonormal";
  if (R.determinant() < 0) return "rotation is a reflection";
  return {};
}

// A reader that knows its file, so every failure names the file and the YAML line.
struct Reader {
  std::filesystem::path path;

  int64_t line(const YAML::Node& n) const { return n.Mark().line >= 0 ? n.Mark().line + 1 : 0; }

  YAML::Node get(const YAML::Node& map, const std::string& key, const std::string& where) const {
    const YAML::Node n = map[key];
    if (!n) fail(path, line(map), "missing key '" + where + key + "'");
    return n;
  }

  void only_keys(const YAML::Node& map, const std::set<std::string>& keys, const std::string& where) const {
    if (!map.IsMap()) fail(path, line(map), "'" + where + "' must be a mapping");
    for (const auto& kv : map) {
      if (!kv.first.IsScalar())
        fail(path, line(kv.first), "'" + where + "' has a key that is not a plain name");
      const std::string k = kv.first.Scalar();
      if (!keys.count(k)) fail(path, line(kv.first), "unknown key '" + where + k + "'");
    }
  }

  std::string text(const YAML::Node& n, const std::string& what) const {
    if (!n.IsScalar()) fail(path, line(n), what + ": expected a scalar");
    return n.Scalar();
  }

  double number(const YAML::Node& n, const std::string& what) const {
    return parse_double(text(n, what), path, line(n), what);
  }

  int integer(const YAML::Node& n, const std::string& what, int lo, int hi) const {
    return static_cast<int>(parse_int(text(n, what), path, line(n), what, lo, hi));
  }

  bool boolean(const YAML::Node& n, const std::string& what) const {
    const std::string s = text(n, what);
    if (s == "true") return true;
    if (s == "false") return false;
    fail(path, line(n), what + ": expected true or false, got '" + s + "'");
  }

  std::vector<double> numbers(const YAML::Node& n, const std::string& what) const {
    if (!n.IsSequence()) fail(path, line(n), what + ": expected a list of numbers");
    std::vector<double> v;
    for (const auto& e : n) v.push_back(number(e, what));
    return v;
  }

  Eigen::Matrix4d transform(const YAML::Node& n, const std::string& what) const {
    if (!n.IsSequence() || n.size() != 4) fail(path, line(n), what + ": expected 4 rows of 4 numbers");
    Eigen::Matrix4d T;
    for (int r = 0; r < 4; ++r) {
      const auto row = numbers(n[r], what);
      if (row.size() != 4)
        fail(path, line(n[r]),
             what + ": row " + std::to_string(r) + " has " + std::to_string(row.size()) +
                 " numbers, expected 4");
      for (int c = 0; c < 4; ++c) T(r, c) = row[c];
    }
    const std::string problem = check_rigid(T);
    if (!problem.empty()) fail(path, line(n), what + " is not a rigid transform: " + problem);
    return T;
  }
};

std::string quoted(const std::string& s) {
  std::string out = "\"";
  for (char c : s) {
    if (c == '"' || c == '\\') out.push_back('\\');
    if (c == '\n') {
      out += "\\n";
      continue;
    }
    out.push_back(c);
  }
  return out + "\"";
}

std::string row_text(const Eigen::Matrix4d& T, int r) {
  std::string s = "[";
  for (int c = 0; c < 4; ++c) s += (c ? ", " : "") + format_double(T(r, c));
  return s + "]";
}

}  // namespace

std::string check_scene_config(const SceneConfig& c) {
  const CameraIntrinsics& k = c.camera;
  if (k.width <= 0 || k.height <= 0) return "camera.width/height: must be positive";
  if (!(k.fx > 0) || !(k.fy > 0)) return "camera.fx/fy: must be positive and finite";
  if (!std::isfinite(k.cx) || !std::isfinite(k.cy)) return "camera.cx/cy: must be finite";
  if (k.bit_depth != 8 && k.bit_depth != 16) return "camera.bit_depth: must be 8 or 16";
  const size_t nd = k.distortion.size();
  if (k.model == CameraModel::kPinhole && nd != 0 && nd != 4 && nd != 5)
    return "camera.distortion: pinhole takes 0, 4 (k1 k2 p1 p2) or 5 (+k3) coefficients, got " +
           std::to_string(nd);
  if (k.model == CameraModel::kEquidistant && nd != 0 && nd != 4)
    return "camera.distortion: equidistant takes 0 or 4 (k1 k2 k3 k4) coefficients, got " +
           std::to_string(nd);
  for (double d : k.distortion)
    if (!std::isfinite(d)) return "camera.distortion: non-finite coefficient";
  if (std::string p = check_rigid(c.T_cam_lidar); !p.empty()) return "T_cam_lidar: " + p;
  if (std::string p = check_rigid(c.T_imu_lidar); !p.empty()) return "T_imu_lidar: " + p;
  if (!std::isfinite(c.time_offset_cam_lidar_s)) return "time_offset_cam_lidar_s: must be finite";
  if (!c.world_offset_m.allFinite()) return "world_offset_m: must be finite";
  if (c.intensity_window &&
      !(std::isfinite(c.intensity_window->first) && c.intensity_window->first < c.intensity_window->second &&
        std::isfinite(c.intensity_window->second)))
    return "intensity_window: must be two finite numbers, low < high";
  return {};
}

namespace {
SceneConfig read_scene_yaml_unguarded(const std::filesystem::path& path);
CameraIntrinsics read_camera_block(const Reader& r, const YAML::Node& root);
}  // namespace

SceneConfig read_scene_yaml(const std::filesystem::path& path) {
  try {
    return read_scene_yaml_unguarded(path);
  } catch (const YAML::Exception& e) {  // anything yaml-cpp throws past our own checks (bad conversions, ...)
    fail(path, e.mark.line >= 0 ? e.mark.line + 1 : 0, "YAML: " + e.msg);
  }
}

CameraIntrinsics read_camera_yaml(const std::filesystem::path& path) {
  try {
    if (!std::filesystem::exists(path)) fail(path, 0, "file does not exist");
    const YAML::Node root = YAML::LoadFile(path.string());
    const Reader r{path};
    SceneConfig c;
    c.camera = read_camera_block(r, root);
    const std::string problem = check_scene_config(c);
    if (!problem.empty()) fail(path, r.line(root), problem);
    return c.camera;
  } catch (const YAML::Exception& e) {
    fail(path, e.mark.line >= 0 ? e.mark.line + 1 : 0, "YAML: " + e.msg);
  }
}

namespace {

CameraIntrinsics read_camera_block(const Reader& r, const YAML::Node& root) {
  const std::filesystem::path& path = r.path;
  CameraIntrinsics camera;
  const YAML::Node cam = r.get(root, "camera", "");
  r.only_keys(cam, {"model", "width", "height", "fx", "fy", "cx", "cy", "distortion", "bit_depth"},
              "camera.");
  const std::string model = r.text(r.get(cam, "model", "camera."), "camera.model");
  if (model == "pinhole")
    camera.model = CameraModel::kPinhole;
  else if (model == "equidistant")
    camera.model = CameraModel::kEquidistant;
  else
    fail(path, r.line(cam["model"]), "camera.model: '" + model + "' is not pinhole or equidistant");
  camera.width = r.integer(r.get(cam, "width", "camera."), "camera.width", 1, 1 << 16);
  camera.height = r.integer(r.get(cam, "height", "camera."), "camera.height", 1, 1 << 16);
  camera.fx = r.number(r.get(cam, "fx", "camera."), "camera.fx");
  camera.fy = r.number(r.get(cam, "fy", "camera."), "camera.fy");
  camera.cx = r.number(r.get(cam, "cx", "camera."), "camera.cx");
  camera.cy = r.number(r.get(cam, "cy", "camera."), "camera.cy");
  camera.distortion = r.numbers(r.get(cam, "distortion", "camera."), "camera.distortion");
  camera.bit_depth = r.integer(r.get(cam, "bit_depth", "camera."), "camera.bit_depth", 8, 16);
  return camera;
}

SceneConfig read_scene_yaml_unguarded(const std::filesystem::path& path) {
  if (!std::filesystem::exists(path)) fail(path, 0, "file does not exist");
  YAML::Node root;
  try {
    root = YAML::LoadFile(path.string());
  } catch (const YAML::ParserException& e) {
    fail(path, e.mark.line + 1, "YAML syntax: " + e.msg);
  } catch (const YAML::BadFile&) {
    fail(path, 0, "cannot open for reading");
  }
  const Reader r{path};
  r.only_keys(root,
              {"format", "version", "units", "camera", "T_cam_lidar", "T_imu_lidar",
               "time_offset_cam_lidar_s", "poses_frame", "poses_origin", "lidar_map", "lidar_holdout_every",
               "world_offset_m", "intensity_window", "source"},
              "");
  if (r.text(r.get(root, "format", ""), "format") != "litgs-scene")
    fail(path, r.line(root["format"]), "format: expected 'litgs-scene'");
  r.integer(r.get(root, "version", ""), "version", 1, 1);
  const YAML::Node units = r.get(root, "units", "");
  r.only_keys(units, {"length", "time", "angle"}, "units.");
  const std::pair<const char*, const char*> expected_units[] = {
      {"length", "m"}, {"time", "s"}, {"angle", "rad"}};
  for (const auto& [key, unit] : expected_units)
    if (r.text(r.get(units, key, "units."), key) != unit)
      fail(path, r.line(units[key]), std::string("units.") + key + ": only '" + unit + "' is supported");

  SceneConfig c;
  c.camera = read_camera_block(r, root);
  c.T_cam_lidar = r.transform(r.get(root, "T_cam_lidar", ""), "T_cam_lidar");
  c.T_imu_lidar = r.transform(r.get(root, "T_imu_lidar", ""), "T_imu_lidar");
  c.time_offset_cam_lidar_s = r.number(r.get(root, "time_offset_cam_lidar_s", ""), "time_offset_cam_lidar_s");
  const std::string frame = r.text(r.get(root, "poses_frame", ""), "poses_frame");
  if (frame == "camera")
    c.poses_frame = PoseFrame::kCamera;
  else if (frame == "imu")
    c.poses_frame = PoseFrame::kImu;
  else
    fail(path, r.line(root["poses_frame"]), "poses_frame: '" + frame + "' is not camera or imu");
  if (root["poses_origin"]) {
    const std::string origin = r.text(root["poses_origin"], "poses_origin");
    if (origin == "odometry")
      c.poses_origin = PoseOrigin::kOdometry;
    else if (origin == "absolute")
      c.poses_origin = PoseOrigin::kAbsolute;
    else
      fail(path, r.line(root["poses_origin"]), "poses_origin: '" + origin + "' is not odometry or absolute");
  }
  c.has_lidar_map = r.boolean(r.get(root, "lidar_map", ""), "lidar_map");
  if (root["lidar_holdout_every"])
    c.lidar_holdout_every = r.integer(root["lidar_holdout_every"], "lidar_holdout_every", 0, 1 << 20);
  const auto offset = r.numbers(r.get(root, "world_offset_m", ""), "world_offset_m");
  if (offset.size() != 3) fail(path, r.line(root["world_offset_m"]), "world_offset_m: expected 3 numbers");
  c.world_offset_m = {offset[0], offset[1], offset[2]};
  if (root["intensity_window"]) {
    const auto w = r.numbers(root["intensity_window"], "intensity_window");
    if (w.size() != 2) fail(path, r.line(root["intensity_window"]), "intensity_window: expected [low, high]");
    c.intensity_window = std::make_pair(w[0], w[1]);
  }
  if (root["source"]) c.source = r.text(root["source"], "source");
  const std::string problem = check_scene_config(c);
  if (!problem.empty()) fail(path, r.line(root), problem);
  return c;
}

}  // namespace

std::string camera_yaml_block(const CameraIntrinsics& k) {
  std::ostringstream out;
  out << "camera:\n"
      << "  model: " << (k.model == CameraModel::kPinhole ? "pinhole" : "equidistant")
      << "  # pinhole | equidistant (fisheye)\n"
      << "  width: " << k.width << "\n  height: " << k.height << "\n"
      << "  fx: " << format_double(k.fx) << "\n  fy: " << format_double(k.fy) << "\n"
      << "  cx: " << format_double(k.cx) << "  # pixels; the centre of the top-left pixel is (0, 0)\n"
      << "  cy: " << format_double(k.cy) << "\n  distortion: [";
  for (size_t i = 0; i < k.distortion.size(); ++i) out << (i ? ", " : "") << format_double(k.distortion[i]);
  out << "]  # pinhole: k1 k2 p1 p2 [k3] (OpenCV); equidistant: k1 k2 k3 k4\n"
      << "  bit_depth: " << k.bit_depth << "  # of the thermal images\n";
  return out.str();
}

void write_scene_yaml(const std::filesystem::path& path, const SceneConfig& c) {
  const std::string problem = check_scene_config(c);
  if (!problem.empty()) throw std::invalid_argument("write_scene_yaml: " + problem);
  write_file_atomic(path, [&](std::ostream& out) {
    out << "# LIT-GS scene description: see docs/scene-format.md\n"
        << "format: litgs-scene\nversion: 1\nunits: {length: m, time: s, angle: rad}\n"
        << camera_yaml_block(c.camera) << "T_cam_lidar:  # maps LiDAR points into the camera frame\n";
    for (int r = 0; r < 4; ++r) out << "  - " << row_text(c.T_cam_lidar, r) << "\n";
    out << "T_imu_lidar:  # maps LiDAR points into the IMU frame\n";
    for (int r = 0; r < 4; ++r) out << "  - " << row_text(c.T_imu_lidar, r) << "\n";
    out << "time_offset_cam_lidar_s: " << format_double(c.time_offset_cam_lidar_s)
        << "  # seconds: t_lidar = t_cam + offset\n"
        << "poses_frame: " << (c.poses_frame == PoseFrame::kCamera ? "camera" : "imu")
        << "  # poses.txt holds T_world_cam (camera) or T_world_imu (imu)\n"
        << "poses_origin: " << (c.poses_origin == PoseOrigin::kAbsolute ? "absolute" : "odometry")
        << "  # odometry (drifts: a relative prior) or absolute (a global solution: a prior per pose)\n"
        << "lidar_map: " << (c.has_lidar_map ? "true" : "false") << "  # lidar/map.pcd present\n"
        << "lidar_holdout_every: " << c.lidar_holdout_every
        << "  # scans 0, N, 2N, ... left out of lidar/map.pcd (0: none); lidar/heldout.pcd holds them\n"
        << "world_offset_m: [" << format_double(c.world_offset_m.x()) << ", "
        << format_double(c.world_offset_m.y()) << ", " << format_double(c.world_offset_m.z())
        << "]  # original coordinates = scene coordinates + this\n";
    if (c.intensity_window)
      out << "intensity_window: [" << format_double(c.intensity_window->first) << ", "
          << format_double(c.intensity_window->second)
          << "]  # raw counts stretched to [0, 1] in training, shared by the blocks of a partition\n";
    out << "source: " << quoted(c.source) << "\n";
  });
}

}  // namespace litgs::io
