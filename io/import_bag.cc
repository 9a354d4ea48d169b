#include "io/import_bag.h"

#include <Eigen/Geometry>
#include <algorithm>
#include <cctype>
#include <map>
#include <stdexcept>

#include "io/error.h"
#include "io/image.h"
#include "io/m2dgr_calib.h"
#include "io/pcd.h"
#include "io/scene.h"
#include "io/text.h"
#include "io/tum.h"

namespace litgs::io {
namespace fs = std::filesystem;

void BagImportOptions::check() const {
  if (bag.empty()) throw std::invalid_argument("bag: required");
  if (calib.empty()) throw std::invalid_argument("calib: required (M2DGR calibration_results.txt)");
  if (out.empty()) throw std::invalid_argument("out: required");
  if (topics.thermal.empty()) throw std::invalid_argument("topics.thermal: required");
  if (image_extension != ".png" && image_extension != ".tiff")
    throw std::invalid_argument("image_extension: must be .png or .tiff, got " + image_extension);
}

std::string m2dgr_imu_block(const std::string& topic) {
  std::string t = topic;
  for (char& c : t) c = static_cast<char>(std::tolower(static_cast<unsigned char>(c)));
  if (t.find("handsfree") != std::string::npos) return "Handsfree IMU";
  if (t.find("camera") != std::string::npos || t.find("realsense") != std::string::npos)
    return "realsense d435i IMU";
  if (t.find("xsens") != std::string::npos || t == "/imu/data") return "Xsens IMU";
  return "";
}

BagImportReport import_bag(const BagImportOptions& o) {
  o.check();
  BagImportReport report;
  const M2dgrCamera cam = read_m2dgr_camera(o.calib, o.calib_block);
  if (!cam.has_intrinsics || cam.width == 0 || cam.height == 0)
    fail(o.calib, 0, "block '" + o.calib_block + "' lacks intrinsics or an image size");
  if (!cam.has_extrinsic) fail(o.calib, 0, "block '" + o.calib_block + "' lacks its extrinsic [to LIDAR]");
  for (const auto& n : cam.notes) report.notes.push_back("calibration: " + n);

  Scene scene;
  CameraIntrinsics& k = scene.config.camera;
  k.model = CameraModel::kPinhole;
  k.width = cam.width;
  k.height = cam.height;
  k.fx = cam.fx;
  k.fy = cam.fy;
  k.cx = cam.cx;
  k.cy = cam.cy;
  k.distortion = cam.distortion;
  Eigen::Matrix4d T_cam_lidar = Eigen::Matrix4d::Identity();
  T_cam_lidar.topLeftCorner<3, 3>() = cam.T_lidar_cam.topLeftCorner<3, 3>().transpose();
  T_cam_lidar.topRightCorner<3, 1>() =
      -cam.T_lidar_cam.topLeftCorner<3, 3>().transpose() * cam.T_lidar_cam.topRightCorner<3, 1>();
  scene.config.T_cam_lidar = T_cam_lidar;
  const std::string imu_block = o.imu_block == "auto" ? m2dgr_imu_block(o.topics.imu) : o.imu_block;
  if (imu_block.empty() || imu_block == "none") {
    report.notes.push_back("T_imu_lidar is identity: " +
                           (imu_block.empty()
                                ? "the IMU topic '" + o.topics.imu + "' names no IMU block of " +
                                      o.calib.filename().string() + " (--imu-block NAME)"
                                : std::string("--imu-block none")));
  } else {
    const M2dgrCamera imu = read_m2dgr_camera(o.calib, imu_block);
    if (!imu.has_extrinsic) fail(o.calib, 0, "block '" + imu_block + "' lacks its extrinsic [to LIDAR]");
    // "Extrinsic [to LIDAR]" maps the sensor's points into the LiDAR frame: T_lidar_imu.
    Eigen::Matrix4d T_imu_lidar = Eigen::Matrix4d::Identity();
    T_imu_lidar.topLeftCorner<3, 3>() = imu.T_lidar_cam.topLeftCorner<3, 3>().transpose();
    T_imu_lidar.topRightCorner<3, 1>() =
        -imu.T_lidar_cam.topLeftCorner<3, 3>().transpose() * imu.T_lidar_cam.topRightCorner<3, 1>();
    scene.config.T_imu_lidar = T_imu_lidar;
    report.notes.push_back("T_imu_lidar from the block '" + imu_block + "' (IMU topic " + o.topics.imu +
                           "): the IMU sits " + format_double(imu.T_lidar_cam.topRightCorner<3, 1>().norm()) +
                           " m from the LiDAR");
  }

  // One pass over the bag; frames and scans are staged as files, keyed by time.
  const fs::path staging = o.out / ".bag-staging";
  fs::remove_all(staging);
  fs::create_directories(staging / "thermal");
  fs::create_directories(staging / "scans");
  std::map<double, fs::path> frames, scans;
  std::vector<TumPose> odom;
  RosBagHandlers h;
  int bit_depth = 0;
  h.thermal = [&](double t, Image im) {
    const fs::path where = o.bag;
    im = single_channel(std::move(im), where);
    if (im.width != k.width || im.height != k.height)
      fail(o.bag, 0,
           "thermal frame at " + format_double(t) + " is " + std::to_string(im.width) + "x" +
               std::to_string(im.height) + ", the calibration says " + std::to_string(k.width) + "x" +
               std::to_string(k.height));
    if (!bit_depth) bit_depth = im.bit_depth;
    if (im.bit_depth != bit_depth) fail(o.bag, 0, "thermal frames of different bit depths");
    const fs::path p = staging / "thermal" / (std::to_string(frames.size()) + ".png");
    if (!frames.emplace(t, p).second) fail(o.bag, 0, "two thermal frames at " + format_double(t));
    write_image(p, im);
  };
  if (o.scans)
    h.lidar = [&](double t, PointCloud c) {
      const fs::path p = staging / "scans" / (std::to_string(scans.size()) + ".pcd");
      if (!scans.emplace(t, p).second) fail(o.bag, 0, "two LiDAR scans at " + format_double(t));
      write_pcd(p, c);
    };
  h.imu = [&](const ImuSample& s) { scene.imu.push_back(s); };
  h.odom = [&](const TumPose& p) { odom.push_back(p); };
  report.messages = read_ros_bag(o.bag, o.topics, h, {.reindex = o.reindex});
  if (const RosBagRecovery& r = report.messages.recovery; r.used)
    report.notes.push_back("reindexed: " + std::to_string(r.chunks) + " complete chunks read in file order" +
                           (r.unread_bytes
                                ? "; the last " + std::to_string(r.unread_bytes) +
                                      " bytes were not (an unfinished chunk or index): " + r.stopped_at
                                : "; nothing left unread"));
  if (frames.empty()) fail(o.bag, 0, "no message on the thermal topic '" + o.topics.thermal + "'");
  k.bit_depth = bit_depth;

  // IMU samples in time order (bags are ordered by receive time; duplicates dropped).
  std::stable_sort(scene.imu.begin(), scene.imu.end(),
                   [](const ImuSample& a, const ImuSample& b) { return a.t_s < b.t_s; });
  scene.imu.erase(std::unique(scene.imu.begin(), scene.imu.end(),
                              [](const ImuSample& a, const ImuSample& b) { return a.t_s == b.t_s; }),
                  scene.imu.end());

  // Trajectory.
  if (!odom.empty()) {
    std::stable_sort(odom.begin(), odom.end(),
                     [](const TumPose& a, const TumPose& b) { return a.t_s < b.t_s; });
    for (const auto& p : odom)
      if (scene.poses.empty() || p.t_s > scene.poses.back().t_s) scene.poses.push_back(p);
    report.notes.push_back("poses from " + o.topics.odom);
  } else if (!o.poses.empty()) {
    scene.poses = read_tum(o.poses);
  } else {
    fail(o.bag, 0, "no trajectory: the bag has no odometry topic messages and no --poses file was given");
  }
  scene.config.poses_frame = o.poses_frame;
  if (!o.ground_truth.empty()) {
    GroundTruth gt;
    gt.poses = read_tum(o.ground_truth);
    scene.gt = gt;
  }
  scene.config.has_lidar_map = false;
  scene.config.source = "bag import of " + o.bag.filename().string() + " with " + o.calib.filename().string();

  std::vector<fs::path> frame_files, scan_files;
  for (const auto& [t, p] : frames) {
    scene.frames.push_back({t, frame_file_name(t, o.image_extension)});
    frame_files.push_back(p);
  }
  for (const auto& [t, p] : scans) {
    scene.scans.push_back({t, {}});
    scan_files.push_back(p);
  }
  SceneWriteOptions wo;
  wo.image_extension = o.image_extension;
  write_scene(
      o.out, scene, [&](size_t i) { return read_image(frame_files[i]); },
      [&](size_t i) { return read_pcd(scan_files[i]); }, wo);
  fs::remove_all(staging);
  report.frames = scene.frames.size();
  report.scans = scene.scans.size();
  report.imu = scene.imu.size();
  report.poses = scene.poses.size();
  return report;
}

}  // namespace litgs::io
