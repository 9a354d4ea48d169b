// libFuzzer target: io::read_ros_bag (ROS 1 bags: the record, chunk and index structure and the four
// message types it decodes: sensor_msgs/Image, PointCloud2, Imu and nav_msgs/Odometry). The topics are the
// ones litgs_fuzz_seeds writes; every decoded message is checked for consistency (Image::check,
// PointCloud::check, finite IMU and pose values), so a decoder that returns a malformed object is a finding
// too (and so is a non-finite IMU value or position, which the reader documents as an error). Each input is
// read through the index and again without it (reindex, the recovery of a recording cut short).
#include <cmath>
#include <cstdlib>

#include "io/ros_bag.h"
#include "tests/fuzz/fuzz_util.h"

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  using namespace litgs::io;
  const auto path = litgs::fuzz::write_temp("in.bag", data, size);
  RosBagTopics topics;
  topics.thermal = "/thermal";
  topics.lidar = "/lidar";
  topics.imu = "/imu";
  topics.odom = "/odom";
  RosBagHandlers h;
  // A std::invalid_argument from check() escapes and is reported as a finding.
  h.thermal = [](double, Image image) { image.check(); };
  h.lidar = [](double, PointCloud cloud) {
    cloud.check();
    for (const auto& p : cloud.positions)
      if (!p.allFinite()) std::abort();  // documented: non-finite points are dropped
  };
  h.imu = [](const ImuSample& s) {
    if (!s.gyro_rad_s.allFinite() || !s.accel_m_s2.allFinite() || !std::isfinite(s.t_s)) std::abort();
  };
  h.odom = [](const TumPose& p) {
    if (!p.p_world.allFinite() || !std::isfinite(p.t_s)) std::abort();
    if (!(std::abs(p.q_world_body.norm() - 1) < 1e-6)) std::abort();  // normalized unit quaternions only
  };
  // Through the index, and without it (`import bag --reindex`: the records in file order).
  litgs::fuzz::expect_only_io_error([&] { read_ros_bag(path, topics, h); });
  return litgs::fuzz::expect_only_io_error([&] { read_ros_bag(path, topics, h, {.reindex = true}); });
}
