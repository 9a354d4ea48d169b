#include "io/import_colmap.h"

#include <Eigen/Geometry>
#include <algorithm>
#include <cmath>
#include <limits>
#include <map>
#include <stdexcept>

#include "io/error.h"
#include "io/image.h"
#include "io/scene.h"
#include "io/text.h"

namespace litgs::io {
namespace fs = std::filesystem;
namespace {

// Where a model's cameras came from, for error messages.
fs::path cameras_file(const fs::path& model) {
  return fs::exists(model / "cameras.bin") && fs::exists(model / "images.bin") ? model / "cameras.bin"
                                                                               : model / "cameras.txt";
}
fs::path images_file(const fs::path& model) {
  return fs::exists(model / "cameras.bin") && fs::exists(model / "images.bin") ? model / "images.bin"
                                                                               : model / "images.txt";
}

}  // namespace

void ColmapImportOptions::check() const {
  if (model.empty()) throw std::invalid_argument("model: required");
  if (images.empty()) throw std::invalid_argument("images: required");
  if (out.empty()) throw std::invalid_argument("out: required");
  if (!fs::is_directory(model)) throw std::invalid_argument("model: not a directory: " + model.string());
  if (!fs::is_directory(images)) throw std::invalid_argument("images: not a directory: " + images.string());
  if (image_extension != ".png" && image_extension != ".tiff")
    throw std::invalid_argument("image_extension: must be .png or .tiff, got " + image_extension);
  if (world_offset_m && !world_offset_m->allFinite())
    throw std::invalid_argument("world_offset_m: must be finite");
  if (!(anchor_min_error_px > 0) || !std::isfinite(anchor_min_error_px))
    throw std::invalid_argument("anchor_min_error_px: must be finite and > 0");
}

CameraIntrinsics scene_camera_from_colmap(const ColmapCamera& c, const fs::path& file) {
  const auto& p = c.params;
  if (static_cast<int>(p.size()) != colmap_model_num_params(c.model))
    fail(file, 0, "camera " + std::to_string(c.id) + ": wrong parameter count");
  CameraIntrinsics k;
  k.model = CameraModel::kPinhole;
  k.width = static_cast<int>(c.width);
  k.height = static_cast<int>(c.height);
  const auto set = [&](double fx, double fy, double cx, double cy) {
    k.fx = fx;
    k.fy = fy;
    k.cx = cx - 0.5;  // COLMAP: centre of the top-left pixel at (0.5, 0.5); scene: (0, 0)
    k.cy = cy - 0.5;
  };
  switch (c.model) {
    case ColmapCameraModel::kSimplePinhole:
      set(p[0], p[0], p[1], p[2]);
      break;
    case ColmapCameraModel::kPinhole:
      set(p[0], p[1], p[2], p[3]);
      break;
    case ColmapCameraModel::kSimpleRadial:
      set(p[0], p[0], p[1], p[2]);
      k.distortion = {p[3], 0, 0, 0};
      break;
    case ColmapCameraModel::kRadial:
      set(p[0], p[0], p[1], p[2]);
      k.distortion = {p[3], p[4], 0, 0};
      break;
    case ColmapCameraModel::kOpenCv:
      set(p[0], p[1], p[2], p[3]);
      k.distortion = {p[4], p[5], p[6], p[7]};
      break;
    case ColmapCameraModel::kFullOpenCv:
      if (p[9] != 0 || p[10] != 0 || p[11] != 0)
        fail(file, 0,
             "camera " + std::to_string(c.id) +
                 ": FULL_OPENCV with a rational part (k4 k5 k6 not 0) has no place in the scene's pinhole "
                 "camera");
      set(p[0], p[1], p[2], p[3]);
      k.distortion = {p[4], p[5], p[6], p[7], p[8]};
      break;
    case ColmapCameraModel::kOpenCvFisheye:
      k.model = CameraModel::kEquidistant;
      set(p[0], p[1], p[2], p[3]);
      k.distortion = {p[4], p[5], p[6], p[7]};
      break;
    default:
      fail(file, 0,
           "camera " + std::to_string(c.id) + ": COLMAP model " + colmap_model_name(c.model) +
               " is not supported (SIMPLE_PINHOLE, PINHOLE, SIMPLE_RADIAL, RADIAL, OPENCV, FULL_OPENCV "
               "without "
               "k4..k6, OPENCV_FISHEYE are)");
  }
  if (std::all_of(k.distortion.begin(), k.distortion.end(), [](double d) { return d == 0; }))
    k.distortion.clear();
  return k;
}

ColmapCamera colmap_camera_from_scene(const CameraIntrinsics& k, uint32_t id) {
  ColmapCamera c;
  c.id = id;
  c.width = static_cast<uint64_t>(k.width);
  c.height = static_cast<uint64_t>(k.height);
  const double cx = k.cx + 0.5, cy = k.cy + 0.5;  // scene (0, 0) -> COLMAP (0.5, 0.5) pixel centres
  const auto& d = k.distortion;
  if (k.model == CameraModel::kEquidistant) {
    c.model = ColmapCameraModel::kOpenCvFisheye;
    c.params = {k.fx, k.fy, cx, cy, 0, 0, 0, 0};
    for (size_t i = 0; i < d.size() && i < 4; ++i) c.params[4 + i] = d[i];
  } else if (d.empty()) {
    c.model = ColmapCameraModel::kPinhole;
    c.params = {k.fx, k.fy, cx, cy};
  } else if (d.size() == 4) {
    c.model = ColmapCameraModel::kOpenCv;
    c.params = {k.fx, k.fy, cx, cy, d[0], d[1], d[2], d[3]};
  } else if (d.size() == 5) {
    c.model = ColmapCameraModel::kFullOpenCv;
    c.params = {k.fx, k.fy, cx, cy, d[0], d[1], d[2], d[3], d[4], 0, 0, 0};
  } else {
    throw std::invalid_argument("camera.distortion: " + std::to_string(d.size()) +
                                " coefficients have no COLMAP model");
  }
  return c;
}

ColmapImportReport import_colmap(const ColmapImportOptions& o) {
  o.check();
  const ColmapModel model = read_colmap_model(o.model);
  ColmapImportReport report;
  if (model.images.empty()) fail(images_file(o.model), 0, "no registered image");

  // One scene camera: every image's camera converts to the same intrinsics.
  Scene scene;
  CameraIntrinsics& k = scene.config.camera;
  const fs::path cam_file = cameras_file(o.model);
  const ColmapCamera& first = model.cameras.at(model.images.front().camera_id);
  k = scene_camera_from_colmap(first, cam_file);
  for (const auto& im : model.images) {
    const ColmapCamera& c = model.cameras.at(im.camera_id);
    if (c.id == first.id) continue;
    const CameraIntrinsics other = scene_camera_from_colmap(c, cam_file);
    if (other.model != k.model || other.width != k.width || other.height != k.height || other.fx != k.fx ||
        other.fy != k.fy || other.cx != k.cx || other.cy != k.cy || other.distortion != k.distortion)
      fail(cam_file, 0,
           "images use cameras " + std::to_string(first.id) + " and " + std::to_string(c.id) +
               " with different parameters: a scene has one camera");
  }

  // Timestamps: image name stems if all are numbers, else image ids.
  bool names_are_times = true;
  for (const auto& im : model.images) {
    double t = 0;
    if (!try_parse_double(fs::path(im.name).stem().string(), t)) names_are_times = false;
  }
  if (!names_are_times)
    report.notes.push_back("image names are not all timestamps: each frame's timestamp is its image id");

  struct Entry {
    const ColmapImage* image;
    Eigen::Matrix4d T_world_cam;
  };
  std::map<double, Entry> by_time;
  Eigen::Vector3d mean = Eigen::Vector3d::Zero();
  for (const auto& im : model.images) {
    double t = static_cast<double>(im.id);
    if (names_are_times) try_parse_double(fs::path(im.name).stem().string(), t);
    const Eigen::Matrix4d T = im.T_world_cam();
    mean += T.topRightCorner<3, 1>() / static_cast<double>(model.images.size());
    const auto [it, inserted] = by_time.emplace(t, Entry{&im, T});
    if (!inserted)
      fail(images_file(o.model), 0,
           "images '" + it->second.image->name + "' and '" + im.name + "' have the same timestamp " +
               format_double(t));
  }
  report.world_offset_m = o.world_offset_m ? *o.world_offset_m : Eigen::Vector3d(mean.array().round());
  scene.config.world_offset_m = report.world_offset_m;
  scene.config.poses_frame = PoseFrame::kCamera;
  scene.config.poses_origin = PoseOrigin::kAbsolute;  // a global photogrammetric solution
  scene.config.has_lidar_map = false;
  scene.config.source =
      "colmap import of " + o.model.string() + "; no LiDAR or IMU (extrinsics are identity placeholders)";

  std::vector<fs::path> image_paths;
  for (const auto& [t, e] : by_time) {
    const fs::path path = o.images / e.image->name;
    if (!fs::exists(path))
      fail(path, 0,
           "image '" + e.image->name + "' of image id " + std::to_string(e.image->id) + " is missing");
    const ImageInfo info = read_image_info(path);
    if (info.width != k.width || info.height != k.height)
      fail(path, 0,
           "image is " + std::to_string(info.width) + "x" + std::to_string(info.height) + ", its camera is " +
               std::to_string(k.width) + "x" + std::to_string(k.height));
    if (image_paths.empty()) k.bit_depth = info.bit_depth;
    if (info.bit_depth != k.bit_depth)
      fail(path, 0,
           "bit depth " + std::to_string(info.bit_depth) + " differs from the first frame's " +
               std::to_string(k.bit_depth));
    image_paths.push_back(path);
    scene.frames.push_back({t, frame_file_name(t, o.image_extension)});
    TumPose pose;
    pose.t_s = t;
    pose.p_world = e.T_world_cam.topRightCorner<3, 1>() - report.world_offset_m;
    pose.q_world_body = e.image->q_cam_world.conjugate();
    scene.poses.push_back(pose);
  }

  if (o.points_as_anchors && !model.points.empty()) {
    std::map<uint32_t, const ColmapImage*> images;
    for (const auto& im : model.images) images[im.id] = &im;
    const double f = 0.5 * (k.fx + k.fy);
    size_t without_track = 0;
    for (const auto& p : model.points) {
      double depth_sum = 0;
      int depth_n = 0;
      for (const auto& t : p.track) {
        const ColmapImage& im = *images.at(t.image_id);
        const double z = (im.q_cam_world * p.xyz + im.t_cam_world).z();
        if (z > 0) {
          depth_sum += z;
          ++depth_n;
        }
      }
      double depth = depth_n ? depth_sum / depth_n : 0;
      if (!depth_n) {
        ++without_track;
        depth = std::numeric_limits<double>::infinity();
        for (const auto& [t, e] : by_time)
          depth = std::min(depth, (e.T_world_cam.topRightCorner<3, 1>() - p.xyz).norm());
      }
      const double sigma = std::max(std::max(p.error_px, o.anchor_min_error_px) * depth / f, 1e-6);
      Anchor a;
      a.p_world = p.xyz - report.world_offset_m;
      a.cov_m2 = Eigen::Matrix3d::Identity() * sigma * sigma;
      scene.anchors.push_back(a);
    }
    report.anchors = scene.anchors.size();
    report.notes.push_back(
        std::to_string(report.anchors) +
        " points3D written as anchors (isotropic covariance from the reprojection error)" +
        (without_track ? "; " + std::to_string(without_track) +
                             " without a track in front of a camera use the distance to the nearest camera"
                       : std::string()));
  }

  SceneWriteOptions write_options;
  write_options.image_extension = o.image_extension;
  write_scene(
      o.out, scene, [&](size_t i) { return single_channel(read_image(image_paths[i]), image_paths[i]); }, {},
      write_options);
  report.frames = scene.frames.size();
  return report;
}

}  // namespace litgs::io
