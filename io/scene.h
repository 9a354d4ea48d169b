// The scene directory: the one input format of every later stage (docs/scene-format.md).
//
//   scene.yaml              camera, extrinsics, time offset, pose frame, recentring offset
//   thermal/<t>.png|.tiff   8- or 16-bit single-channel frames, the stem is the timestamp in seconds
//   poses.txt               TUM trajectory of the camera or the IMU (scene.yaml says which)
//   lidar/map.pcd           world-frame LiDAR map (absent when scene.yaml says lidar_map: false)
//   lidar/scans/<t>.pcd     optional sensor-frame scans
//   imu.csv                 optional IMU samples
//   anchors.txt             optional visual map points with covariances
//   gt/                     optional ground truth: poses.txt, map.pcd, planes.txt
#pragma once

#include <filesystem>
#include <functional>
#include <optional>
#include <vector>

#include "io/image.h"
#include "io/point_cloud.h"
#include "io/scene_types.h"

namespace litgs::io {

struct Scene {
  SceneConfig config;
  std::vector<SceneFrame> frames;  // by increasing time; pixels are loaded on demand (load_frame)
  std::vector<TumPose> poses;      // poses.txt
  std::optional<PointCloud> map;   // lidar/map.pcd, if config.has_lidar_map and it was loaded
  std::vector<SceneScan> scans;    // lidar/scans/, listed by increasing time, loaded on demand
  std::vector<ImuSample> imu;      // imu.csv (empty if absent)
  std::vector<Anchor> anchors;     // anchors.txt (empty if absent)
  std::optional<GroundTruth> gt;   // gt/ (if the folder exists)
};

struct SceneReadOptions {
  bool check_images = true;  // read every frame's header: size, bit depth and channels must match the camera
  bool load_map = true;      // read lidar/map.pcd (false: only check that it exists)
};

// Reads and checks a scene directory. IoError (file, line, problem) on: a missing scene.yaml, thermal/ or
// poses.txt; lidar/map.pcd missing although scene.yaml says lidar_map: true (or present although it says
// false); a frame or scan name that is not a timestamp, an unknown image extension, two files with the same
// timestamp; an image whose size, bit depth or channel count disagrees with the camera; and every error of
// the file readers (field counts, NaN/Inf, non-monotonic timestamps, non-positive-definite covariances).
Scene read_scene(const std::filesystem::path& dir, const SceneReadOptions& options = {});

// Loads frame i's pixels (and checks them against the camera as read_scene does).
Image load_frame(const std::filesystem::path& dir, const Scene& scene, size_t i);

// Pixels come from callbacks so that a long sequence never sits in memory at once.
using FrameImageSource = std::function<Image(size_t frame_index)>;
using ScanSource = std::function<PointCloud(size_t scan_index)>;

struct SceneWriteOptions {
  std::string image_extension = ".png";  // ".png" or ".tiff"
  bool double_precision_maps = true;     // map and gt map positions as float64 (exact round trip)
};

// Writes `scene` into dir (created if needed). frames[i].image and scans[i].file are ignored: the names
// are derived from the timestamps (frame_file_name). Every file is written to a temporary name and renamed,
// scene.yaml last, so a failure never destroys a file already there. std::invalid_argument (naming the
// frame) if an image disagrees with the camera or a scan source is missing; IoError on file errors.
void write_scene(const std::filesystem::path& dir, const Scene& scene, const FrameImageSource& images,
                 const ScanSource& scans = {}, const SceneWriteOptions& options = {});

// "thermal/<t>.png": the shortest decimal text that reads back as exactly t_s.
std::filesystem::path frame_file_name(double t_s, const std::string& extension = ".png");

}  // namespace litgs::io
