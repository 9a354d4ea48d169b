// ROS 1 bags: the four message types a LiDAR-inertial-thermal scene needs, converted to io/ types.
//
// Reading (ros_bag_read.cc) is our own parser of the bag format 2.0 and of the messages' serialization,
// which checks every length and offset before it reads or allocates (rosbag_storage's reader trusts them:
// see the .cc), and needs no ROS library. Writing (RosBagWriter, for tests and fuzz seeds) goes through
// Debian's rosbag_storage, built only when the ROS packages are found (ci/setup installs
// librosbag-storage-dev, libsensor-msgs-dev, libnav-msgs-dev); ros_bag_writer_available() says so at run
// time. This header stays C++17 and no ROS header leaks out of ros_bag.cc: the generated ROS 1 message
// headers use std::allocator<void>::rebind, removed in C++20, so ros_bag.cc is compiled as C++17 in its own
// target.
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

// True when this build can write bags (RosBagWriter); reading is always available.
bool ros_bag_writer_available();

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
  std::function<void(double t_s, PointCloud cloud)> lidar;  // x y z [intensity] [time]; non-finite dropped
  std::function<void(const ImuSample& sample)> imu;
  std::function<void(const TumPose& pose)> odom;  // pose.pose of the message: T_world_child
};

// What reading without the index (RosBagReadOptions::reindex) found.
struct RosBagRecovery {
  bool used = false;
  size_t chunks = 0;          // complete chunks read
  uint64_t unread_bytes = 0;  // from the first record that did not fit or parse to the end of the file
  std::string stopped_at;     // why reading stopped there (empty: it reached the end)
};

struct RosBagCounts {
  size_t thermal = 0, lidar = 0, imu = 0, odom = 0;
  RosBagRecovery recovery;
};

struct RosBagReadOptions {
  // Ignore the index and read the records in file order (a recording cut short has no index, or one that
  // points past its end), keeping the messages of every complete chunk, as `rosbag reindex` does.
  bool reindex = false;
};

// Reads the topics of `topics` (empty names are skipped) through the bag's index (or, with
// options.reindex, by reading its records in order: RosBagRecovery), in time order (ties in file order),
// like rosbag::View. Chunks may be uncompressed, bz2 or lz4. IoError naming the bag (and the
// byte, or the message's index, topic and time) on a missing, unindexed (unfinished recording), corrupt or
// truncated bag, a bag format other than 2.0, a topic whose type (or definition MD5) is not the expected
// one, or a message that cannot be converted (its bytes do not match its type's layout, unknown image
// encoding, short data, a point cloud without x y z float fields, a field beyond point_step or in
// big-endian, a non-finite IMU value or odometry position, a non-unit orientation). Topics absent from the
// bag give no messages (check the counts).
RosBagCounts read_ros_bag(const std::filesystem::path& bag, const RosBagTopics& topics,
                          const RosBagHandlers& handlers, const RosBagReadOptions& options = {});

enum class RosBagCompression { kNone, kBz2, kLz4 };

// Writes a bag with rosbag_storage (for tests and fuzz seeds). Images: 1 channel -> mono8/mono16, 3 -> rgb8/
// rgb16; clouds: x y z float32 [intensity float32] [time float32 (extra "time")]. IoError on library errors,
// or when the build has none (ros_bag_writer_available()).
class RosBagWriter {
 public:
  explicit RosBagWriter(const std::filesystem::path& bag,
                        RosBagCompression compression = RosBagCompression::kNone);
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
