// `litgs-engine export colmap|tum`: a scene directory into the formats other tools read (COLMAP, 3DGS
// trainers, evo). docs/scene-format.md, "Exporting".
#pragma once

#include <filesystem>
#include <optional>
#include <string>
#include <vector>

#include "io/scene.h"

namespace litgs::io {

// The camera pose T_world_cam (scene coordinates, i.e. recentred) at each frame of `scene`, or nullopt where
// none can be had. Camera poses (poses_frame: camera) are looked up at the frame's time; IMU poses at the
// frame's time + time_offset_cam_lidar_s (the LiDAR/IMU clock; the IMU is assumed to share the LiDAR's
// clock) and converted with T_world_cam = T_world_imu * T_imu_lidar * inverse(T_cam_lidar). A time equal to
// a pose's is used as is; between two poses, translation is interpolated linearly and rotation by slerp;
// outside the trajectory, or next to a pose of unknown rotation, there is no pose.
std::vector<std::optional<Eigen::Matrix4d>> camera_poses_at_frames(const Scene& scene);

// `poses`, held in config.poses_frame, as poses of the IMU (the body frame of LIO odometry): camera poses
// become T_world_imu = T_world_cam * T_cam_lidar * inverse(T_imu_lidar), stamped t + time_offset_cam_lidar_s
// (the IMU shares the LiDAR's clock); IMU poses come back as they are. IoError naming `file` where a camera
// pose of unknown rotation would need the lever arm.
std::vector<TumPose> imu_trajectory(const SceneConfig& config, const std::vector<TumPose>& poses,
                                    const std::filesystem::path& file);

struct ColmapExportOptions {
  std::filesystem::path scene;  // scene directory to read
  std::filesystem::path out;    // folder to write: out/images/<frame>.png|.tiff, out/sparse/0/*.bin|.txt
  bool binary = false;          // .bin (true) or .txt model files
  // false: original world coordinates (scene + world_offset_m), comparable with other tools' data;
  // true: the scene's recentred coordinates (what float32 trainers prefer).
  bool recentred = false;
  // points3D from anchors.txt if the scene has anchors, else from the LiDAR map if it has one, keeping
  // every k-th point so that at most this many are written (0: no points3D at all).
  size_t max_points = 200000;

  // Throws std::invalid_argument naming the bad field.
  void check() const;
};

struct ColmapExportReport {
  size_t images = 0;                // frames with a pose, written
  size_t skipped_without_pose = 0;  // frames outside the trajectory
  size_t points = 0;                // points3D written
  std::vector<std::string> notes;
};

// Writes a COLMAP model with one camera (colmap_camera_from_scene; PINHOLE, OPENCV, FULL_OPENCV or
// OPENCV_FISHEYE), one image per frame with a pose (camera_poses_at_frames), named as the scene's frame
// file ("<t>.png": `import colmap` reads the timestamp back), qvec/tvec = cam_from_world, empty POINTS2D;
// points3D without tracks, error -1 (unknown), gray colour 128. Frame files are copied byte for byte.
// IoError on unreadable scenes; std::invalid_argument on bad options.
ColmapExportReport export_colmap(const ColmapExportOptions& options);

struct TumExportOptions {
  std::filesystem::path scene;  // scene directory to read
  std::filesystem::path out;    // TUM file to write
  // false: poses.txt as stored (camera or IMU, scene.yaml's poses_frame); true: the camera pose at every
  // frame's timestamp (camera_poses_at_frames; frames without a pose are left out).
  bool camera = false;
  bool ground_truth = false;  // gt/poses.txt instead of poses.txt (not with camera)
  bool imu = false;           // the poses (or the truth) as IMU poses (imu_trajectory; not with camera)
  bool recentred = false;     // as in ColmapExportOptions

  // Throws std::invalid_argument naming the bad field.
  void check() const;
};

// Writes the TUM file atomically; returns the number of poses written. IoError on unreadable scenes or a
// missing gt/poses.txt.
size_t export_tum(const TumExportOptions& options);

}  // namespace litgs::io
