// `litgs-engine import bag`: a ROS 1 bag (io/ros_bag.h) plus M2DGR's calibration into a scene directory
// (docs/scene-format.md, "Importing from a ROS 1 bag").
#pragma once

#include <filesystem>
#include <string>
#include <vector>

#include "io/ros_bag.h"
#include "io/scene_types.h"

namespace litgs::io {

struct BagImportOptions {
  std::filesystem::path bag;    // ROS 1 bag
  std::filesystem::path calib;  // M2DGR calibration_results.txt (camera intrinsics and camera-to-LiDAR)
  std::string calib_block = "Cam-thermal";  // the camera block of `calib`
  // The IMU block of `calib` whose "Extrinsic [to LIDAR]" gives T_imu_lidar: "auto" picks it by the IMU
  // topic (handsfree -> "Handsfree IMU", camera -> "realsense d435i IMU", xsens or /imu/data -> "Xsens
  // IMU"); "none": identity (said in the notes); else a block name.
  std::string imu_block = "auto";
  std::filesystem::path out;  // scene directory to write (created; must not hold other frames)
  RosBagTopics topics;        // M2DGR's names by default; odom empty: none
  // TUM trajectory for poses.txt when the bag has no odometry topic (e.g. an estimator's output);
  // poses_frame says which frame both describe.
  std::filesystem::path poses;
  PoseFrame poses_frame = PoseFrame::kImu;
  std::filesystem::path ground_truth;  // optional TUM file -> gt/poses.txt (0 0 0 0 rotations allowed)
  bool scans = true;                   // write every LiDAR message as lidar/scans/<t>.pcd
  // Read the bag without its index (a recording cut short: RosBagReadOptions::reindex); the notes say how
  // many chunks were read and how many bytes at the end were not.
  bool reindex = false;
  std::string image_extension = ".png";  // of the written frames: ".png" or ".tiff"

  // Throws std::invalid_argument naming the bad field.
  void check() const;
};

struct BagImportReport {
  RosBagCounts messages;  // per topic, as read
  size_t frames = 0, scans = 0, imu = 0, poses = 0;
  std::vector<std::string> notes;
};

// Writes the scene: thermal frames (single_channel: 3-channel frames whose channels are equal, as M2DGR
// publishes them, become one channel), LiDAR scans in the sensor frame, imu.csv, poses from the odometry
// topic or options.poses, intrinsics and T_cam_lidar = inverse of the block's "Extrinsic [to LIDAR]"
// (T_lidar_cam). No LiDAR map (lidar_map: false; accumulate the scans with poses later), T_imu_lidar the
// inverse of the IMU block's "Extrinsic [to LIDAR]" (imu_block; the block used is in the notes), time
// offset 0. Frames and scans are staged under
// OUT/.bag-staging while the bag is read once, so memory stays bounded. IoError naming the bag, the
// message or the file on bad input; no thermal message, or no trajectory, is an error.
BagImportReport import_bag(const BagImportOptions& options);

// The IMU block imu_block = "auto" picks for an IMU topic; empty when the topic names no known IMU.
std::string m2dgr_imu_block(const std::string& imu_topic);

}  // namespace litgs::io
