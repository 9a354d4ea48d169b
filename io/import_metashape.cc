#include "io/import_metashape.h"

#include <Eigen/Geometry>
#include <cmath>
#include <map>
#include <stdexcept>

#include "io/error.h"
#include "io/image.h"
#include "io/metashape.h"
#include "io/scene.h"
#include "io/text.h"

namespace litgs::io {
namespace fs = std::filesystem;
namespace {

// "HH-MM-SS-mmm" at the start of a label -> seconds of the day; false if the label does not start so.
bool label_time(const std::string& label, double& t_s) {
  if (label.size() < 12 || label[2] != '-' || label[5] != '-' || label[8] != '-') return false;
  for (int i : {0, 1, 3, 4, 6, 7, 9, 10, 11})
    if (label[i] < '0' || label[i] > '9') return false;
  if (label.size() > 12 && label[12] >= '0' && label[12] <= '9') return false;
  const auto num = [&](int i, int n) { return std::stoi(label.substr(i, n)); };
  const int h = num(0, 2), m = num(3, 2), s = num(6, 2), ms = num(9, 3);
  if (h > 23 || m > 59 || s > 60) return false;
  t_s = h * 3600.0 + m * 60.0 + s + ms / 1000.0;
  return true;
}

fs::path find_image(const fs::path& dir, const std::string& label) {
  for (const char* ext :
       {".tiff", ".tif", ".png", ".jpg", ".jpeg", ".TIFF", ".TIF", ".PNG", ".JPG", ".JPEG"}) {
    const fs::path p = dir / (label + ext);
    if (fs::exists(p)) return p;
  }
  fail(dir / label, 0, "no image for camera '" + label + "' (looked for .tiff, .tif, .png, .jpg, .jpeg)");
}

}  // namespace

void MetashapeImportOptions::check() const {
  if (xml.empty()) throw std::invalid_argument("xml: required");
  if (images.empty()) throw std::invalid_argument("images: required");
  if (out.empty()) throw std::invalid_argument("out: required");
  if (!fs::is_directory(images)) throw std::invalid_argument("images: not a directory: " + images.string());
  if (image_extension != ".png" && image_extension != ".tiff")
    throw std::invalid_argument("image_extension: must be .png or .tiff, got " + image_extension);
  if (world_offset_m && !world_offset_m->allFinite())
    throw std::invalid_argument("world_offset_m: must be finite");
}

MetashapeImportReport import_metashape(const MetashapeImportOptions& o) {
  o.check();
  const MetashapeDocument doc = read_metashape_xml(o.xml);
  MetashapeImportReport report;

  // Aligned cameras, one sensor.
  std::vector<const MetashapeCamera*> cameras;
  for (const auto& c : doc.cameras) {
    if (!c.T_chunk_cam) {
      ++report.skipped_unaligned;
      continue;
    }
    if (!cameras.empty() && c.sensor_id != cameras.front()->sensor_id)
      fail(o.xml, 0,
           "cameras of several sensors (" + std::to_string(cameras.front()->sensor_id) + " and " +
               std::to_string(c.sensor_id) + "): a scene has one camera");
    cameras.push_back(&c);
  }
  if (cameras.empty()) fail(o.xml, 0, "no aligned camera (none has a <transform>)");
  const MetashapeSensor& sensor = *doc.sensor(cameras.front()->sensor_id);
  MetashapeCalibration cal;
  if (!o.calibration.empty()) {
    cal = read_metashape_calibration(o.calibration);
    report.notes.push_back("calibration from " + o.calibration.string());
  } else if (sensor.calibration) {
    cal = *sensor.calibration;
  } else {
    fail(o.xml, 0, "sensor " + std::to_string(sensor.id) + " has no <calibration> (pass a calibration file)");
  }
  if (cal.k4 != 0 || cal.b2 != 0)
    fail(o.calibration.empty() ? o.xml : o.calibration, 0,
         "k4 and skew b2 have no place in the scene's pinhole camera");

  Scene scene;
  CameraIntrinsics& k = scene.config.camera;
  k.model = CameraModel::kPinhole;
  k.width = cal.width;
  k.height = cal.height;
  k.fx = cal.f + cal.b1;  // b1: affinity, x focal length = f + b1
  k.fy = cal.f;
  // Metashape: corner origin, principal point as an offset from the centre; scene: pixel-centre origin.
  k.cx = 0.5 * cal.width + cal.cx - 0.5;
  k.cy = 0.5 * cal.height + cal.cy - 0.5;
  if (cal.k1 != 0 || cal.k2 != 0 || cal.k3 != 0 || cal.p1 != 0 || cal.p2 != 0) {
    k.distortion = {cal.k1, cal.k2, cal.p2, cal.p1};  // OpenCV order: Metashape's p1/p2 swapped
    if (cal.k3 != 0) k.distortion.push_back(cal.k3);
  }

  // Timestamps, poses and images, sorted by time.
  std::map<double, std::pair<const MetashapeCamera*, Eigen::Matrix4d>> by_time;
  Eigen::Vector3d mean = Eigen::Vector3d::Zero();
  for (size_t i = 0; i < cameras.size(); ++i) {
    double t = 0;
    if (!label_time(cameras[i]->label, t)) {
      t = static_cast<double>(cameras[i]->id);
      report.notes.push_back("camera '" + cameras[i]->label +
                             "': no HH-MM-SS-mmm label, timestamp = its id " + format_double(t));
    }
    const Eigen::Matrix4d T = doc.T_world_cam(*cameras[i]);
    mean += T.topRightCorner<3, 1>() / static_cast<double>(cameras.size());
    if (!by_time.emplace(t, std::make_pair(cameras[i], T)).second)
      fail(o.xml, 0, "two cameras with the timestamp " + format_double(t) + " ('" + cameras[i]->label + "')");
  }
  report.world_offset_m = o.world_offset_m ? *o.world_offset_m : Eigen::Vector3d(mean.array().round());
  scene.config.world_offset_m = report.world_offset_m;
  scene.config.poses_frame = PoseFrame::kCamera;
  scene.config.poses_origin = PoseOrigin::kAbsolute;  // a global photogrammetric solution
  scene.config.has_lidar_map = false;
  scene.config.source = "metashape import of " + o.xml.filename().string() +
                        "; timestamps are seconds of the day from the camera labels; no LiDAR or IMU "
                        "(extrinsics are identity placeholders)";

  std::vector<fs::path> image_paths;
  for (const auto& [t, entry] : by_time) {
    const auto& [camera, T] = entry;
    const fs::path image = find_image(o.images, camera->label);
    const ImageInfo info = read_image_info(image);
    if (info.width != k.width || info.height != k.height || info.channels != 1)
      fail(image, 0,
           "image is " + std::to_string(info.width) + "x" + std::to_string(info.height) + " with " +
               std::to_string(info.channels) + " channel(s); the calibration is " + std::to_string(k.width) +
               "x" + std::to_string(k.height) + ", 1 channel");
    if (image_paths.empty()) k.bit_depth = info.bit_depth;
    if (info.bit_depth != k.bit_depth)
      fail(image, 0,
           "bit depth " + std::to_string(info.bit_depth) + " differs from the first frame's " +
               std::to_string(k.bit_depth));
    image_paths.push_back(image);
    scene.frames.push_back({t, frame_file_name(t, o.image_extension)});
    TumPose pose;
    pose.t_s = t;
    pose.p_world = T.topRightCorner<3, 1>() - report.world_offset_m;
    pose.q_world_body = Eigen::Quaterniond(Eigen::Matrix3d(T.topLeftCorner<3, 3>())).normalized();
    scene.poses.push_back(pose);
  }
  SceneWriteOptions write_options;
  write_options.image_extension = o.image_extension;
  write_scene(
      o.out, scene, [&](size_t i) { return read_image(image_paths[i]); }, {}, write_options);
  report.frames = scene.frames.size();
  return report;
}

}  // namespace litgs::io
