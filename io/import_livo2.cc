#include "io/import_livo2.h"

#include <yaml-cpp/yaml.h>

#include <Eigen/Geometry>
#include <Eigen/SVD>
#include <algorithm>
#include <cmath>
#include <stdexcept>

#include "io/error.h"
#include "io/image.h"
#include "io/pcd.h"
#include "io/scene.h"
#include "io/text.h"
#include "io/tum.h"

namespace litgs::io {
namespace fs = std::filesystem;
namespace {

// The configuration files, searched for keys at any depth (ROS 1 namespaces, ROS 2 ros__parameters).
class Config {
 public:
  explicit Config(const std::vector<fs::path>& files) {
    for (const auto& f : files) {
      if (!fs::exists(f)) fail(f, 0, "configuration file does not exist");
      try {
        docs_.push_back({f, YAML::LoadFile(f.string())});
      } catch (const YAML::ParserException& e) {
        fail(f, e.mark.line + 1, std::string("YAML syntax: ") + e.msg);
      } catch (const YAML::Exception& e) {
        fail(f, 0, std::string("cannot read YAML: ") + e.what());
      }
    }
  }

  struct Found {
    fs::path file;
    YAML::Node node;
    int64_t line() const { return node.Mark().line >= 0 ? node.Mark().line + 1 : 0; }
  };

  std::optional<Found> find(const std::string& key) const {
    for (const auto& [file, doc] : docs_)
      if (auto n = find_in(doc, key)) return Found{file, *n};
    return std::nullopt;
  }

  Found require(const std::string& key) const {
    if (auto f = find(key)) return *f;
    std::string files;
    for (const auto& [file, doc] : docs_) files += (files.empty() ? "" : ", ") + file.string();
    fail(docs_.empty() ? fs::path("(no config)") : docs_.front().first, 0,
         "key '" + key + "' not found in " + files);
  }

  double number(const std::string& key) const { return number(require(key), key); }
  double number_or(const std::string& key, double fallback) const {
    const auto f = find(key);
    return f ? number(*f, key) : fallback;
  }
  std::string text(const std::string& key) const {
    const Found f = require(key);
    if (!f.node.IsScalar()) fail(f.file, f.line(), key + ": expected a scalar");
    return f.node.Scalar();
  }
  std::vector<double> numbers(const std::string& key, size_t count) const {
    const Found f = require(key);
    if (!f.node.IsSequence() || f.node.size() != count)
      fail(f.file, f.line(), key + ": expected a list of " + std::to_string(count) + " numbers");
    std::vector<double> v;
    for (const auto& e : f.node) {
      if (!e.IsScalar()) fail(f.file, f.line(), key + ": expected numbers");
      v.push_back(parse_double(e.Scalar(), f.file, f.line(), key));
    }
    return v;
  }

 private:
  static double number(const Found& f, const std::string& key) {
    if (!f.node.IsScalar()) fail(f.file, f.line(), key + ": expected a number");
    return parse_double(f.node.Scalar(), f.file, f.line(), key);
  }
  static std::optional<YAML::Node> find_in(const YAML::Node& n, const std::string& key) {
    if (n.IsMap()) {
      if (const YAML::Node v = n[key]) return v;
      for (const auto& kv : n)
        if (auto r = find_in(kv.second, key)) return r;
    } else if (n.IsSequence()) {
      for (const auto& e : n)
        if (auto r = find_in(e, key)) return r;
    }
    return std::nullopt;
  }

  std::vector<std::pair<fs::path, YAML::Node>> docs_;
};

// [R | t] from a row-major 3x3 and a translation; R orthonormalized when off by at most max_error.
Eigen::Matrix4d rigid(const Config& config, const std::string& r_key, const std::string& t_key,
                      double max_error, std::vector<std::string>& notes) {
  const std::vector<double> r = config.numbers(r_key, 9), t = config.numbers(t_key, 3);
  Eigen::Matrix3d R;
  R << r[0], r[1], r[2], r[3], r[4], r[5], r[6], r[7], r[8];
  const double error = (R.transpose() * R - Eigen::Matrix3d::Identity()).norm();
  const auto f = config.require(r_key);
  if (!(error <= max_error) || R.determinant() <= 0)
    fail(f.file, f.line(),
         r_key + " is not a rotation (|R^T R - I| = " + format_double(error) + ", det " +
             format_double(R.determinant()) + ")");
  if (error > 1e-12) {
    const Eigen::JacobiSVD<Eigen::Matrix3d> svd(R, Eigen::ComputeFullU | Eigen::ComputeFullV);
    R = svd.matrixU() * svd.matrixV().transpose();
    notes.push_back(r_key + " orthonormalized (|R^T R - I| was " + format_double(error) + ")");
  }
  Eigen::Matrix4d T = Eigen::Matrix4d::Identity();
  T.topLeftCorner<3, 3>() = R;
  T.topRightCorner<3, 1>() = Eigen::Vector3d(t[0], t[1], t[2]);
  return T;
}

Eigen::Matrix4d rigid_inverse(const Eigen::Matrix4d& T) {
  Eigen::Matrix4d inv = Eigen::Matrix4d::Identity();
  inv.topLeftCorner<3, 3>() = T.topLeftCorner<3, 3>().transpose();
  inv.topRightCorner<3, 1>() = -T.topLeftCorner<3, 3>().transpose() * T.topRightCorner<3, 1>();
  return inv;
}

std::vector<fs::path> files_with(const fs::path& dir, const std::vector<std::string>& extensions) {
  std::vector<fs::path> out;
  if (!fs::is_directory(dir)) return out;
  for (const auto& e : fs::directory_iterator(dir)) {
    std::string ext = e.path().extension().string();
    std::transform(ext.begin(), ext.end(), ext.begin(), [](unsigned char c) { return std::tolower(c); });
    if (e.is_regular_file() && std::find(extensions.begin(), extensions.end(), ext) != extensions.end())
      out.push_back(e.path());
  }
  std::sort(out.begin(), out.end());
  return out;
}

}  // namespace

void Livo2ImportOptions::check() const {
  if (log.empty()) throw std::invalid_argument("log: required");
  if (config.empty()) throw std::invalid_argument("config: at least one YAML file required");
  if (out.empty()) throw std::invalid_argument("out: required");
  if (!fs::is_directory(log)) throw std::invalid_argument("log: not a directory: " + log.string());
  if (image_extension != ".png" && image_extension != ".tiff")
    throw std::invalid_argument("image_extension: must be .png or .tiff, got " + image_extension);
  if (world_offset_m && !world_offset_m->allFinite())
    throw std::invalid_argument("world_offset_m: must be finite");
  if (!(pose_snap_s >= 0) || !std::isfinite(pose_snap_s))
    throw std::invalid_argument("pose_snap_s: must be finite and >= 0");
  if (!(max_rotation_error >= 0) || !std::isfinite(max_rotation_error))
    throw std::invalid_argument("max_rotation_error: must be finite and >= 0");
}

Livo2ImportReport import_livo2(const Livo2ImportOptions& o) {
  o.check();
  Livo2ImportReport report;
  const Config config(o.config);

  // Camera (vikit's loader: every size and intrinsic times `scale`).
  Scene scene;
  CameraIntrinsics& k = scene.config.camera;
  const std::string model = config.text("cam_model");
  if (model != "Pinhole") {
    const auto f = config.require("cam_model");
    fail(f.file, f.line(), "cam_model '" + model + "' is not supported (only Pinhole)");
  }
  const double scale = config.number_or("scale", 1.0);
  if (!(scale > 0)) {
    const auto f = config.require("scale");
    fail(f.file, f.line(), "scale must be > 0");
  }
  const auto size = [&](const std::string& key) {
    const double v = config.number(key) * scale;
    if (!(v >= 1) || v > 1e5 || v != std::round(v)) {
      const auto f = config.require(key);
      fail(f.file, f.line(), key + " times scale is " + format_double(v) + ", not a positive whole size");
    }
    return static_cast<int>(v);
  };
  k.model = CameraModel::kPinhole;
  k.width = size("cam_width");
  k.height = size("cam_height");
  k.fx = config.number("cam_fx") * scale;
  k.fy = config.number("cam_fy") * scale;
  k.cx = config.number("cam_cx") * scale;
  k.cy = config.number("cam_cy") * scale;
  if (scale != 1.0) report.notes.push_back("camera scaled by " + format_double(scale) + " (vikit's scale)");
  k.distortion = {config.number_or("cam_d0", 0), config.number_or("cam_d1", 0), config.number_or("cam_d2", 0),
                  config.number_or("cam_d3", 0)};
  if (const double k3 = config.number_or("cam_d4", 0); k3 != 0) k.distortion.push_back(k3);
  if (std::all_of(k.distortion.begin(), k.distortion.end(), [](double d) { return d == 0; }))
    k.distortion.clear();

  // Extrinsics.
  const Eigen::Matrix4d T_imu_lidar =
      rigid(config, "extrinsic_R", "extrinsic_T", o.max_rotation_error, report.notes);
  const Eigen::Matrix4d T_cam_lidar = rigid(config, "Rcl", "Pcl", o.max_rotation_error, report.notes);
  scene.config.T_imu_lidar = T_imu_lidar;
  scene.config.T_cam_lidar = T_cam_lidar;
  const Eigen::Matrix4d T_imu_cam = T_imu_lidar * rigid_inverse(T_cam_lidar);
  scene.config.time_offset_cam_lidar_s = 0;
  scene.config.poses_frame = PoseFrame::kCamera;

  // Trajectory.
  fs::path trajectory = o.trajectory;
  if (trajectory.empty()) {
    const auto txt = files_with(o.log / "result", {".txt"});
    if (txt.size() != 1)
      fail(
          o.log / "result", 0,
          std::to_string(txt.size()) + " .txt files (expected one TUM trajectory; choose with --trajectory)");
    trajectory = txt.front();
  }
  const std::vector<TumPose> imu_poses = read_tum(trajectory);
  if (imu_poses.empty()) fail(trajectory, 0, "no pose");

  // Map.
  fs::path map_file = o.map;
  std::vector<fs::path> map_files;
  if (!map_file.empty()) {
    map_files = {map_file};
  } else if (fs::exists(o.log / "pcd/all_downsampled_points.pcd")) {
    map_files = {o.log / "pcd/all_downsampled_points.pcd"};
  } else if (fs::exists(o.log / "pcd/all_raw_points.pcd")) {
    map_files = {o.log / "pcd/all_raw_points.pcd"};
  } else {
    map_files = files_with(o.log / "pcd", {".pcd"});
  }
  if (map_files.empty()) fail(o.log / "pcd", 0, "no .pcd map (pass one with --map)");
  PointCloud map;
  bool all_intensity = true;
  std::vector<PointCloud> clouds;
  for (const auto& f : map_files) {
    clouds.push_back(read_pcd(f, {.drop_nonfinite_points = true}));
    all_intensity = all_intensity && clouds.back().intensity.size() == clouds.back().size();
  }
  const Eigen::Vector3d offset = o.world_offset_m ? *o.world_offset_m : Eigen::Vector3d::Zero();
  for (const auto& c : clouds) {
    for (const auto& p : c.positions) map.positions.push_back(p - offset);
    if (all_intensity) map.intensity.insert(map.intensity.end(), c.intensity.begin(), c.intensity.end());
  }
  if (map_files.size() > 1)
    report.notes.push_back("map merged from " + std::to_string(map_files.size()) + " PCD files");
  report.notes.push_back("map: " + map_files.front().filename().string() +
                         (map_files.size() > 1 ? ", ..." : ""));
  report.map_points = map.size();
  scene.map = std::move(map);
  scene.config.has_lidar_map = true;
  scene.config.world_offset_m = offset;

  // Frames with a pose.
  std::vector<fs::path> image_paths;
  std::vector<double> times;
  for (const auto& f : files_with(o.log / "image", {".png", ".tif", ".tiff"})) {
    double t = 0;
    if (!try_parse_double(f.stem().string(), t)) fail(f, 0, "the file name is not a timestamp in seconds");
    times.push_back(t);
    image_paths.push_back(f);
  }
  if (image_paths.empty()) fail(o.log / "image", 0, "no .png/.tif/.tiff frames");
  std::vector<size_t> order(image_paths.size());
  for (size_t i = 0; i < order.size(); ++i) order[i] = i;
  std::sort(order.begin(), order.end(), [&](size_t a, size_t b) { return times[a] < times[b]; });
  std::vector<fs::path> used;
  for (size_t i : order) {
    const auto T_world_imu = tum_pose_at(imu_poses, times[i], o.pose_snap_s);
    if (!T_world_imu) {
      ++report.skipped_no_pose;
      continue;
    }
    if (!scene.frames.empty() && scene.frames.back().t_s == times[i])
      fail(image_paths[i], 0, "same timestamp as " + used.back().filename().string());
    const ImageInfo info = read_image_info(image_paths[i]);
    if (info.width != k.width || info.height != k.height)
      fail(image_paths[i], 0,
           "image is " + std::to_string(info.width) + "x" + std::to_string(info.height) + ", the camera is " +
               std::to_string(k.width) + "x" + std::to_string(k.height));
    if (used.empty()) k.bit_depth = info.bit_depth;
    if (info.bit_depth != k.bit_depth)
      fail(image_paths[i], 0,
           "bit depth " + std::to_string(info.bit_depth) + " differs from the first frame's");
    const Eigen::Matrix4d T_world_cam = *T_world_imu * T_imu_cam;
    TumPose pose;
    pose.t_s = times[i];
    pose.p_world = T_world_cam.topRightCorner<3, 1>() - offset;
    pose.q_world_body = Eigen::Quaterniond(Eigen::Matrix3d(T_world_cam.topLeftCorner<3, 3>())).normalized();
    scene.poses.push_back(pose);
    scene.frames.push_back({times[i], frame_file_name(times[i], o.image_extension)});
    used.push_back(image_paths[i]);
  }
  if (used.empty())
    fail(o.log / "image", 0, "no frame lies within the trajectory of " + trajectory.filename().string());
  if (report.skipped_no_pose)
    report.notes.push_back(std::to_string(report.skipped_no_pose) +
                           " frames outside the trajectory left out");
  scene.config.source = "livo2 import of " + o.log.string() + " (" + trajectory.filename().string() +
                        "): camera poses from IMU poses and the configured extrinsics";

  SceneWriteOptions write_options;
  write_options.image_extension = o.image_extension;
  write_scene(
      o.out, scene, [&](size_t i) { return single_channel(read_image(used[i]), used[i]); }, {},
      write_options);
  report.frames = scene.frames.size();
  return report;
}

}  // namespace litgs::io
