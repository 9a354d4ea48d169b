// RosBagWriter through rosbag_storage, compiled as C++17 (see ros_bag.h). With LITGS_HAVE_ROSBAG undefined,
// the writer throws. Reading is ros_bag_read.cc, which needs no ROS library.
#include "io/ros_bag.h"

#include <cmath>
#include <cstring>
#include <stdexcept>

#include "io/error.h"

#ifdef LITGS_HAVE_ROSBAG
#include <nav_msgs/Odometry.h>
#include <rosbag/bag.h>
#include <sensor_msgs/Image.h>
#include <sensor_msgs/Imu.h>
#include <sensor_msgs/PointCloud2.h>
#endif

namespace litgs::io {
namespace fs = std::filesystem;

#ifdef LITGS_HAVE_ROSBAG

bool ros_bag_writer_available() {
  return true;
}

struct RosBagWriter::Impl {
  fs::path path;
  rosbag::Bag bag;
};

RosBagWriter::RosBagWriter(const fs::path& bag, RosBagCompression compression) : impl_(new Impl) {
  impl_->path = bag;
  try {
    impl_->bag.open(bag.string(), rosbag::bagmode::Write);
    impl_->bag.setCompression(compression == RosBagCompression::kBz2   ? rosbag::compression::BZ2
                              : compression == RosBagCompression::kLz4 ? rosbag::compression::LZ4
                                                                       : rosbag::compression::Uncompressed);
  } catch (const rosbag::BagException& e) {
    fail(bag, 0, std::string("rosbag: ") + e.what());
  }
}

RosBagWriter::~RosBagWriter() = default;

void RosBagWriter::image(const std::string& topic, double t_s, const Image& image) {
  image.check();
  sensor_msgs::Image m;
  m.header.stamp = ros::Time(t_s);
  m.width = static_cast<uint32_t>(image.width);
  m.height = static_cast<uint32_t>(image.height);
  const int bytes = image.bit_depth / 8;
  static const char* enc8[] = {"", "mono8", "", "rgb8", "rgba8"};
  static const char* enc16[] = {"", "mono16", "", "rgb16", "rgba16"};
  m.encoding = bytes == 1 ? enc8[image.channels] : enc16[image.channels];
  if (m.encoding.empty()) throw std::invalid_argument("RosBagWriter: 2-channel images have no encoding");
  m.is_bigendian = 0;
  m.step = static_cast<uint32_t>(image.width * image.channels * bytes);
  for (uint16_t v : image.data) {
    m.data.push_back(static_cast<uint8_t>(v & 0xff));
    if (bytes == 2) m.data.push_back(static_cast<uint8_t>(v >> 8));
  }
  impl_->bag.write(topic, m.header.stamp, m);
}

void RosBagWriter::cloud(const std::string& topic, double t_s, const PointCloud& cloud) {
  cloud.check();
  sensor_msgs::PointCloud2 m;
  m.header.stamp = ros::Time(t_s);
  m.height = 1;
  m.width = static_cast<uint32_t>(cloud.size());
  const bool intensity = !cloud.intensity.empty();
  const ScalarField* time = cloud.field("time");
  std::vector<std::string> names = {"x", "y", "z"};
  if (intensity) names.push_back("intensity");
  if (time) names.push_back("time");
  for (uint32_t k = 0; k < names.size(); ++k) {
    sensor_msgs::PointField f;
    f.name = names[k];
    f.offset = 4 * k;
    f.datatype = sensor_msgs::PointField::FLOAT32;
    f.count = 1;
    m.fields.push_back(f);
  }
  m.point_step = static_cast<uint32_t>(4 * names.size());
  m.row_step = m.point_step * m.width;
  m.is_dense = true;
  m.data.resize(m.row_step);
  for (size_t i = 0; i < cloud.size(); ++i) {
    std::vector<float> v = {static_cast<float>(cloud.positions[i].x()),
                            static_cast<float>(cloud.positions[i].y()),
                            static_cast<float>(cloud.positions[i].z())};
    if (intensity) v.push_back(cloud.intensity[i]);
    if (time) v.push_back(static_cast<float>(time->values[i]));
    std::memcpy(m.data.data() + i * m.point_step, v.data(), m.point_step);
  }
  impl_->bag.write(topic, m.header.stamp, m);
}

void RosBagWriter::imu(const std::string& topic, const ImuSample& s) {
  sensor_msgs::Imu m;
  m.header.stamp = ros::Time(s.t_s);
  m.orientation.w = 1;
  m.angular_velocity.x = s.gyro_rad_s.x();
  m.angular_velocity.y = s.gyro_rad_s.y();
  m.angular_velocity.z = s.gyro_rad_s.z();
  m.linear_acceleration.x = s.accel_m_s2.x();
  m.linear_acceleration.y = s.accel_m_s2.y();
  m.linear_acceleration.z = s.accel_m_s2.z();
  impl_->bag.write(topic, m.header.stamp, m);
}

void RosBagWriter::odom(const std::string& topic, const TumPose& p) {
  nav_msgs::Odometry m;
  m.header.stamp = ros::Time(p.t_s);
  m.pose.pose.position.x = p.p_world.x();
  m.pose.pose.position.y = p.p_world.y();
  m.pose.pose.position.z = p.p_world.z();
  m.pose.pose.orientation.x = p.q_world_body.x();
  m.pose.pose.orientation.y = p.q_world_body.y();
  m.pose.pose.orientation.z = p.q_world_body.z();
  m.pose.pose.orientation.w = p.q_world_body.w();
  impl_->bag.write(topic, m.header.stamp, m);
}

void RosBagWriter::close() {
  impl_->bag.close();
}

#else  // no rosbag_storage in this build

namespace {
[[noreturn]] void unavailable(const fs::path& path) {
  fail(path, 0,
       "this build has no ROS bag support (install librosbag-storage-dev libsensor-msgs-dev libnav-msgs-dev, "
       "ci/setup, and reconfigure)");
}
}  // namespace

bool ros_bag_writer_available() {
  return false;
}
struct RosBagWriter::Impl {};
RosBagWriter::RosBagWriter(const fs::path& bag, RosBagCompression) {
  unavailable(bag);
}
RosBagWriter::~RosBagWriter() = default;
void RosBagWriter::image(const std::string&, double, const Image&) {}
void RosBagWriter::cloud(const std::string&, double, const PointCloud&) {}
void RosBagWriter::imu(const std::string&, const ImuSample&) {}
void RosBagWriter::odom(const std::string&, const TumPose&) {}
void RosBagWriter::close() {}

#endif

}  // namespace litgs::io
