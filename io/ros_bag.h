// ROS 1 bags through Debian's rosbag_storage library: the four message types a LiDAR-inertial-thermal
// scene needs, converted to io/ types. No ROS header leaks out of io/ros_bag.cc.
//
// Built only when the ROS packages are found (ci/setup installs librosbag-storage-dev, libsensor-msgs-dev,
// libnav-msgs-dev); ros_bag_available() says so at run time. This header (and the .cc) stay C++17: the
// generated ROS 1 message headers use std::allocator<void>::rebind, removed in C++20, so ros_bag.cc is
// compiled as C++17 in its own target.
#pragma once

#include <filesystem>
#include <functional>
#include <memory>
#include <string>

#include "io/image.h"
#include "io/point_cloud.h"
#include "io/scene_types.h"
#include "io/tum.h"

namespace litgs::io {

// True when this build can read and write bags.
bool ros_bag_available();

struct RosBagTopics {
  std::string thermal = "/thermal_image_raw";  // sensor_msgs/Image
  std::string lidar = "/velodyne_points";      // sensor_msgs/PointCloud2
  std::string imu = "/handsfree/imu";          // sensor_msgs/Imu
  std::string odom;                            // nav_msgs/Odometry; empty: none
};

// Called per message in bag order; a missing handler skips that topic. Times are the header stamps
// (seconds); a zero stamp falls back to the bag's receive time.
struct RosBagHandlers {
  std::function<void(double t_s, Image image)> thermal;     // channels and depth as the encoding says
  std::function<void(double t_s, PointCloud cloud)> lidar;  // x y z [intensity]; non-finite points dropped
  std::function<void(const ImuSample& sample)> imu;
  std::function<void(const TumPose& pose)> odom;  // pose.pose of the message: T_world_child
};

struct RosBagCounts {
  size_t thermal = 0, lidar = 0, imu = 0, odom = 0;
};

// Reads the topics of `topics` (empty names are skipped). IoError naming the bag (and the message's topic,
// index and time) on a missing or corrupt bag, a topic whose type is not the expected one, or a message
// that cannot be converted (unknown image encoding, short data, a point cloud without x y z float fields
// or in big-endian). Topics absent from the bag give no messages (check the counts).
RosBagCounts read_ros_bag(const std::filesystem::path& bag, const RosBagTopics& topics,
                          const RosBagHandlers& handlers);

// Writes a bag with rosbag_storage (for tests and exports). Images: 1 channel -> mono8/mono16, 3 -> rgb8/
// rgb16; clouds: x y z float32 [intensity float32]. IoError on library errors.
class RosBagWriter {
 public:
  explicit RosBagWriter(const std::filesystem::path& bag);
  ~RosBagWriter();
  RosBagWriter(const RosBagWriter&) = delete;
  RosBagWriter& operator=(const RosBagWriter&) = delete;

  void image(const std::string& topic, double t_s, const Image& image);
  void cloud(const std::string& topic, double t_s, const PointCloud& cloud);
  void imu(const std::string& topic, const ImuSample& sample);
  void odom(const std::string& topic, const TumPose& pose);
  void close();

 private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
};

}  // namespace litgs::io
