// The value types of a scene directory (see docs/scene-format.md), apart from the files' readers.
#pragma once

#include <Eigen/Core>
#include <filesystem>
#include <optional>
#include <string>
#include <utility>
#include <vector>

#include "io/point_cloud.h"
#include "io/tum.h"

namespace litgs::io {

enum class CameraModel {
  kPinhole,      // distortion: OpenCV radtan k1 k2 p1 p2 [k3] (or none)
  kEquidistant,  // fisheye (OpenCV fisheye / Kalibr equidistant): k1 k2 k3 k4 (or none)
};

// Which moving frame the poses of poses.txt describe: T_world_cam or T_world_imu.
enum class PoseFrame { kCamera, kImu };
// Where poses.txt came from. kOdometry: an estimator that drifts (FAST-LIVO2, LIO, a bag's odometry, the
// synthetic estimator): good between nearby frames, not globally. kAbsolute: a global solution (Metashape,
// COLMAP with control points): each pose is a prior of its own. refine chooses its priors by it.
enum class PoseOrigin { kOdometry, kAbsolute };

// The thermal camera. Pixel coordinates put the centre of the top-left pixel at (0, 0) (OpenCV).
struct CameraIntrinsics {
  CameraModel model = CameraModel::kPinhole;
  int width = 0, height = 0;              // pixels
  double fx = 0, fy = 0, cx = 0, cy = 0;  // pixels
  std::vector<double> distortion;         // see CameraModel; empty = none
  int bit_depth = 16;                     // of the thermal images: 8 or 16
};

// scene.yaml. Units are fixed: metres, seconds, radians.
struct SceneConfig {
  CameraIntrinsics camera;
  Eigen::Matrix4d T_cam_lidar = Eigen::Matrix4d::Identity();  // maps LiDAR points into the camera frame
  Eigen::Matrix4d T_imu_lidar = Eigen::Matrix4d::Identity();  // maps LiDAR points into the IMU frame
  double time_offset_cam_lidar_s = 0;  // seconds: the LiDAR-clock time of a camera stamp is t_cam + offset
  PoseFrame poses_frame = PoseFrame::kCamera;
  PoseOrigin poses_origin = PoseOrigin::kOdometry;  // scene.yaml `poses_origin`, optional (odometry)
  bool has_lidar_map = true;  // false: the scene has no lidar/map.pcd (e.g. a photogrammetry import)
  // scene.yaml `lidar_holdout_every`, optional (0): the scans that lidar/map.pcd leaves out so that the
  // geometry can be measured against measurements the training map never held (is_heldout_scan).
  int lidar_holdout_every = 0;
  // Recentring: original world coordinates = scene world coordinates + world_offset_m (keeps float32 work
  // near the origin for data sets that sit far from it).
  Eigen::Vector3d world_offset_m = Eigen::Vector3d::Zero();
  // scene.yaml `intensity_window: [low, high]`, optional: the raw counts a 16-bit frame is stretched from,
  // shared by every part of a larger scene (`partition` writes the whole scene's into each block, so that the
  // blocks' models share one intensity scale). Absent: training takes percentiles of the scene's own frames.
  std::optional<std::pair<double, double>> intensity_window;
  std::string source;  // free text: where the scene came from
};

// Scan i of lidar/scans/ (by increasing time) is held out of the map when this holds: scans 0, N, 2N, ...
inline constexpr int kDefaultLidarHoldoutEvery = 8;
inline bool is_heldout_scan(size_t scan_index, int holdout_every) {
  return holdout_every > 0 && scan_index % static_cast<size_t>(holdout_every) == 0;
}
// The map of the held-out scans, built as lidar/map.pcd is (host/lidar_map): the reference of `eval`'s
// geometry on scenes without ground truth.
inline constexpr const char* kHeldoutScansMap = "lidar/heldout.pcd";

// One thermal frame: thermal/<t_s>.png|.tiff (the stem is the timestamp).
struct SceneFrame {
  double t_s = 0;
  std::filesystem::path image;  // relative to the scene directory
};

// One LiDAR scan in its sensor frame: lidar/scans/<t_s>.pcd. Listed by the reader, loaded on demand.
struct SceneScan {
  double t_s = 0;
  std::filesystem::path file;  // relative to the scene directory
};

struct ImuSample {
  double t_s = 0;
  Eigen::Vector3d gyro_rad_s = Eigen::Vector3d::Zero();
  Eigen::Vector3d accel_m_s2 = Eigen::Vector3d::Zero();
};

// A visual map point of the upstream estimator with its 3x3 covariance (symmetric positive definite).
struct Anchor {
  Eigen::Vector3d p_world = Eigen::Vector3d::Zero();  // metres
  Eigen::Matrix3d cov_m2 = Eigen::Matrix3d::Identity();
};

// A plane n . x + d = 0 in the world frame, |n| = 1.
struct Plane {
  Eigen::Vector3d n = Eigen::Vector3d::UnitZ();
  double d = 0;
};

// gt/: whatever ground truth the scene has (synthetic scenes: all of it).
struct GroundTruth {
  std::vector<TumPose> poses;     // gt/poses.txt, same frame as poses.txt (empty if absent)
  std::optional<PointCloud> map;  // gt/map.pcd
  std::vector<Plane> planes;      // gt/planes.txt
};

}  // namespace litgs::io
