// `litgs-engine export bag`: a scene directory as a ROS 1 bag laid out like an M2DGR sequence, the inverse
// of `import bag` (docs/scene-format.md, "Exporting"): what a user's recording would look like, so that the
// bag path can be measured end to end on a scene whose truth is known.
#pragma once

#include <filesystem>
#include <string>

#include "io/ros_bag.h"

namespace litgs::io {

struct BagExportOptions {
  std::filesystem::path scene;           // scene directory to read
  std::filesystem::path out;             // .bag file to write (replaced atomically)
  RosBagTopics topics{.odom = "/odom"};  // M2DGR's names; an empty name leaves that stream out
  // false: original world coordinates (scene + world_offset_m), as a recording has them; true: recentred.
  bool recentred = false;

  // Throws std::invalid_argument naming the bad field.
  void check() const;
};

struct BagExportReport {
  size_t frames = 0, scans = 0, imu = 0, odometry = 0;
};

// Writes, each at its own timestamp: every thermal frame as stored (mono8 or mono16), every LiDAR scan in
// the sensor frame (PointCloud2), every imu.csv sample, and poses.txt as nav_msgs/Odometry of the IMU (the
// body frame of LIO odometry such as M2DGR's: imu_trajectory). IoError naming the file on an unreadable
// scene, a scene without scans when the LiDAR topic is asked for, or a build that cannot write bags
// (ros_bag_writer_available()); std::invalid_argument on bad options.
BagExportReport export_bag(const BagExportOptions& options);

}  // namespace litgs::io
