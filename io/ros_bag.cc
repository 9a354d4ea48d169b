// Compiled as C++17 (see ros_bag.h). With LITGS_HAVE_ROSBAG undefined, every entry point throws.
#include "io/ros_bag.h"

#include <cmath>
#include <cstring>
#include <stdexcept>

#include "io/error.h"

#ifdef LITGS_HAVE_ROSBAG
#include <nav_msgs/Odometry.h>
#include <rosbag/bag.h>
#include <rosbag/view.h>
#include <sensor_msgs/Image.h>
#include <sensor_msgs/Imu.h>
#include <sensor_msgs/PointCloud2.h>
#endif

namespace litgs::io {
namespace fs = std::filesystem;

#ifdef LITGS_HAVE_ROSBAG
namespace {

// sensor_msgs/Image encodings -> channels, bytes per channel.
bool encoding_layout(const std::string& e, int& channels, int& bytes) {
  struct L {
    const char* name;
    int channels, bytes;
  };
  static const L layouts[] = {{"mono8", 1, 1}, {"8UC1", 1, 1},   {"mono16", 1, 2}, {"16UC1", 1, 2},
                              {"rgb8", 3, 1},  {"bgr8", 3, 1},   {"8UC3", 3, 1},   {"rgba8", 4, 1},
                              {"bgra8", 4, 1}, {"8UC4", 4, 1},   {"rgb16", 3, 2},  {"bgr16", 3, 2},
                              {"16UC3", 3, 2}, {"rgba16", 4, 2}, {"bgra16", 4, 2}, {"16UC4", 4, 2}};
  for (const auto& l : layouts)
    if (e == l.name) {
      channels = l.channels;
      bytes = l.bytes;
      return true;
    }
  return false;
}

Image to_image(const sensor_msgs::Image& m, const std::string& where) {
  int channels = 0, bytes = 0;
  if (!encoding_layout(m.encoding, channels, bytes))
    throw std::runtime_error(where + ": image encoding '" + m.encoding + "' is not supported");
  const size_t row = static_cast<size_t>(m.width) * channels * bytes;
  if (m.width == 0 || m.height == 0 || m.step < row || m.data.size() < static_cast<size_t>(m.step) * m.height)
    throw std::runtime_error(where + ": image " + std::to_string(m.width) + "x" + std::to_string(m.height) +
                             " step " + std::to_string(m.step) + " with " + std::to_string(m.data.size()) +
                             " bytes is inconsistent");
  Image im;
  im.width = static_cast<int>(m.width);
  im.height = static_cast<int>(m.height);
  im.channels = channels;
  im.bit_depth = 8 * bytes;
  im.data.resize(static_cast<size_t>(m.width) * m.height * channels);
  for (uint32_t y = 0; y < m.height; ++y) {
    const uint8_t* src = m.data.data() + static_cast<size_t>(y) * m.step;
    for (size_t i = 0; i < static_cast<size_t>(m.width) * channels; ++i) {
      uint16_t v = src[i * bytes];
      if (bytes == 2) {
        const uint16_t b0 = src[2 * i], b1 = src[2 * i + 1];
        v = m.is_bigendian ? static_cast<uint16_t>((b0 << 8) | b1) : static_cast<uint16_t>((b1 << 8) | b0);
      }
      im.data[static_cast<size_t>(y) * m.width * channels + i] = v;
    }
  }
  return im;
}

double read_field(const uint8_t* p, uint8_t datatype) {
  switch (datatype) {
    case sensor_msgs::PointField::INT8:
      return static_cast<int8_t>(*p);
    case sensor_msgs::PointField::UINT8:
      return *p;
    case sensor_msgs::PointField::INT16: {
      int16_t v;
      std::memcpy(&v, p, 2);
      return v;
    }
    case sensor_msgs::PointField::UINT16: {
      uint16_t v;
      std::memcpy(&v, p, 2);
      return v;
    }
    case sensor_msgs::PointField::INT32: {
      int32_t v;
      std::memcpy(&v, p, 4);
      return v;
    }
    case sensor_msgs::PointField::UINT32: {
      uint32_t v;
      std::memcpy(&v, p, 4);
      return v;
    }
    case sensor_msgs::PointField::FLOAT32: {
      float v;
      std::memcpy(&v, p, 4);
      return v;
    }
    case sensor_msgs::PointField::FLOAT64: {
      double v;
      std::memcpy(&v, p, 8);
      return v;
    }
    default:
      return NAN;
  }
}

int field_size(uint8_t datatype) {
  switch (datatype) {
    case sensor_msgs::PointField::INT8:
    case sensor_msgs::PointField::UINT8:
      return 1;
    case sensor_msgs::PointField::INT16:
    case sensor_msgs::PointField::UINT16:
      return 2;
    case sensor_msgs::PointField::INT32:
    case sensor_msgs::PointField::UINT32:
    case sensor_msgs::PointField::FLOAT32:
      return 4;
    case sensor_msgs::PointField::FLOAT64:
      return 8;
    default:
      return 0;
  }
}

PointCloud to_cloud(const sensor_msgs::PointCloud2& m, const std::string& where) {
  if (m.is_bigendian) throw std::runtime_error(where + ": big-endian point clouds are not supported");
  const sensor_msgs::PointField* f[4] = {nullptr, nullptr, nullptr, nullptr};
  static const char* names[4] = {"x", "y", "z", "intensity"};
  for (const auto& field : m.fields)
    for (int k = 0; k < 4; ++k)
      if (field.name == names[k]) f[k] = &field;
  for (int k = 0; k < 4; ++k) {
    if (!f[k]) {
      if (k < 3) throw std::runtime_error(where + ": point cloud has no field '" + names[k] + "'");
      continue;
    }
    const int size = field_size(f[k]->datatype);
    if (size == 0 || (k < 3 && f[k]->datatype != sensor_msgs::PointField::FLOAT32 &&
                      f[k]->datatype != sensor_msgs::PointField::FLOAT64))
      throw std::runtime_error(where + ": field '" + names[k] + "' has datatype " +
                               std::to_string(f[k]->datatype) + " (x y z must be float32 or float64)");
    // Subtraction, not offset + size: both are uint32_t, and a forged offset near 2^32 would wrap the sum
    // below point_step and send the reads 4 GiB past the point.
    if (f[k]->offset > m.point_step || static_cast<uint32_t>(size) > m.point_step - f[k]->offset)
      throw std::runtime_error(where + ": field '" + std::string(names[k]) + "' (offset " +
                               std::to_string(f[k]->offset) + ", " + std::to_string(size) +
                               " bytes) lies beyond point_step " + std::to_string(m.point_step));
  }
  const size_t n = static_cast<size_t>(m.width) * m.height;
  if (m.row_step < static_cast<size_t>(m.width) * m.point_step ||
      m.data.size() < static_cast<size_t>(m.row_step) * m.height)
    throw std::runtime_error(where + ": point cloud data is shorter than height * row_step");
  PointCloud c;
  c.positions.reserve(n);
  for (uint32_t r = 0; r < m.height; ++r)
    for (uint32_t i = 0; i < m.width; ++i) {
      const uint8_t* p =
          m.data.data() + static_cast<size_t>(r) * m.row_step + static_cast<size_t>(i) * m.point_step;
      const Eigen::Vector3d x(read_field(p + f[0]->offset, f[0]->datatype),
                              read_field(p + f[1]->offset, f[1]->datatype),
                              read_field(p + f[2]->offset, f[2]->datatype));
      if (!x.allFinite()) continue;
      c.positions.push_back(x);
      if (f[3]) c.intensity.push_back(static_cast<float>(read_field(p + f[3]->offset, f[3]->datatype)));
    }
  return c;
}

double stamp(const ros::Time& header, const ros::Time& received) {
  return header.isZero() ? received.toSec() : header.toSec();
}

}  // namespace

bool ros_bag_available() {
  return true;
}

RosBagCounts read_ros_bag(const fs::path& path, const RosBagTopics& topics, const RosBagHandlers& h) {
  if (!fs::exists(path)) fail(path, 0, "bag does not exist");
  RosBagCounts counts;
  size_t index = 0;
  std::string where;
  try {
    rosbag::Bag bag(path.string(), rosbag::bagmode::Read);
    std::vector<std::string> wanted;
    for (const std::string* t : {&topics.thermal, &topics.lidar, &topics.imu, &topics.odom})
      if (!t->empty()) wanted.push_back(*t);
    rosbag::View view(bag, rosbag::TopicQuery(wanted));
    for (const rosbag::MessageInstance& m : view) {
      ++index;
      where = "message " + std::to_string(index) + " on " + m.getTopic() + " at " +
              std::to_string(m.getTime().toSec());
      const auto expect = [&](const char* type) {
        if (m.getDataType() != type)
          throw std::runtime_error(where + ": type is " + m.getDataType() + ", expected " + type);
      };
      if (m.getTopic() == topics.thermal) {
        expect("sensor_msgs/Image");
        const auto msg = m.instantiate<sensor_msgs::Image>();
        ++counts.thermal;
        if (h.thermal) h.thermal(stamp(msg->header.stamp, m.getTime()), to_image(*msg, where));
      } else if (m.getTopic() == topics.lidar) {
        expect("sensor_msgs/PointCloud2");
        const auto msg = m.instantiate<sensor_msgs::PointCloud2>();
        ++counts.lidar;
        if (h.lidar) h.lidar(stamp(msg->header.stamp, m.getTime()), to_cloud(*msg, where));
      } else if (m.getTopic() == topics.imu) {
        expect("sensor_msgs/Imu");
        const auto msg = m.instantiate<sensor_msgs::Imu>();
        ++counts.imu;
        ImuSample s;
        s.t_s = stamp(msg->header.stamp, m.getTime());
        s.gyro_rad_s = {msg->angular_velocity.x, msg->angular_velocity.y, msg->angular_velocity.z};
        s.accel_m_s2 = {msg->linear_acceleration.x, msg->linear_acceleration.y, msg->linear_acceleration.z};
        if (h.imu) h.imu(s);
      } else if (m.getTopic() == topics.odom) {
        expect("nav_msgs/Odometry");
        const auto msg = m.instantiate<nav_msgs::Odometry>();
        ++counts.odom;
        TumPose p;
        p.t_s = stamp(msg->header.stamp, m.getTime());
        const auto& q = msg->pose.pose.orientation;
        const auto& x = msg->pose.pose.position;
        p.p_world = {x.x, x.y, x.z};
        const Eigen::Quaterniond quat(q.w, q.x, q.y, q.z);
        if (!(std::abs(quat.norm() - 1) < 1e-3))
          throw std::runtime_error(where + ": orientation is not a unit quaternion");
        p.q_world_body = quat.normalized();
        if (h.odom) h.odom(p);
      }
    }
  } catch (const rosbag::BagException& e) {
    fail(path, 0, (where.empty() ? "" : where + ": ") + "rosbag: " + e.what());
  } catch (const ros::Exception& e) {
    fail(path, 0, (where.empty() ? "" : where + ": ") + "ros: " + e.what());
  } catch (const IoError&) {
    throw;
  } catch (const std::runtime_error& e) {
    fail(path, 0, e.what());
  }
  return counts;
}

struct RosBagWriter::Impl {
  fs::path path;
  rosbag::Bag bag;
};

RosBagWriter::RosBagWriter(const fs::path& bag) : impl_(new Impl) {
  impl_->path = bag;
  try {
    impl_->bag.open(bag.string(), rosbag::bagmode::Write);
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
  const char* names[4] = {"x", "y", "z", "intensity"};
  for (uint32_t k = 0; k < (intensity ? 4u : 3u); ++k) {
    sensor_msgs::PointField f;
    f.name = names[k];
    f.offset = 4 * k;
    f.datatype = sensor_msgs::PointField::FLOAT32;
    f.count = 1;
    m.fields.push_back(f);
  }
  m.point_step = intensity ? 16 : 12;
  m.row_step = m.point_step * m.width;
  m.is_dense = true;
  m.data.resize(m.row_step);
  for (size_t i = 0; i < cloud.size(); ++i) {
    float v[4] = {static_cast<float>(cloud.positions[i].x()), static_cast<float>(cloud.positions[i].y()),
                  static_cast<float>(cloud.positions[i].z()), intensity ? cloud.intensity[i] : 0.f};
    std::memcpy(m.data.data() + i * m.point_step, v, m.point_step);
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

bool ros_bag_available() {
  return false;
}
RosBagCounts read_ros_bag(const fs::path& path, const RosBagTopics&, const RosBagHandlers&) {
  unavailable(path);
}
struct RosBagWriter::Impl {};
RosBagWriter::RosBagWriter(const fs::path& bag) {
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
