#include <gtest/gtest.h>

#include <Eigen/Geometry>
#include <cmath>
#include <fstream>
#include <random>

#include "io/file_bytes.h"
#include "io/import_bag.h"
#include "io/m2dgr_calib.h"
#include "io/pcd.h"
#include "io/ros_bag.h"
#include "io/scene.h"
#include "tests/io/io_test.h"

namespace litgs::io {
namespace {

class ImportBagTest : public testing::TempDirTest {
 protected:
  void SetUp() override {
    TempDirTest::SetUp();
    if (!ros_bag_available()) GTEST_FAIL() << "this build has no ROS bag support (ci/setup)";
  }
  static Image thermal(int seed, int channels) {
    Image im;
    im.width = 640;
    im.height = 512;
    im.channels = channels;
    for (int i = 0; i < 640 * 512; ++i)
      for (int c = 0; c < channels; ++c) im.data.push_back(static_cast<uint16_t>((i + seed) % 251));
    return im;
  }
  // A tiny M2DGR-like bag written by rosbag_storage itself: 2 thermal frames (3-channel, as M2DGR
  // publishes them), 2 Velodyne scans (one point NaN), 3 IMU samples, 3 odometry poses.
  std::filesystem::path write_bag() const {
    const auto path = dir_ / "tiny.bag";
    RosBagWriter w(path);
    for (int i = 0; i < 3; ++i) {
      TumPose p;
      p.t_s = 1628410457.0 + 0.1 * i;
      p.p_world = {1.0 * i, 0.5, -0.25 * i};
      p.q_world_body = Eigen::Quaterniond(Eigen::AngleAxisd(0.1 * i, Eigen::Vector3d::UnitZ()));
      w.odom("/odom", p);
      w.imu("/handsfree/imu", {p.t_s + 0.01, {0.01 * i, 0.02, 0.03}, {0.1, 9.81, -0.2 * i}});
    }
    w.image("/thermal_image_raw", 1628410457.05, thermal(1, 3));
    w.image("/thermal_image_raw", 1628410457.15, thermal(2, 3));
    PointCloud c;
    c.positions = {{1, 2, 3}, {NAN, 0, 0}, {4.5, -5, 6}};
    c.intensity = {10, 20, 30};
    w.cloud("/velodyne_points", 1628410457.0, c);
    w.cloud("/velodyne_points", 1628410457.1, c);
    w.close();
    return path;
  }
};

TEST_F(ImportBagTest, ImportsTinyM2dgrLikeBag) {
  BagImportOptions o;
  o.bag = write_bag();
  o.calib = testing::data_dir() / "m2dgr/calibration_results.txt";
  o.out = dir_ / "scene";
  o.topics.odom = "/odom";
  o.ground_truth = testing::data_dir() / "m2dgr/hall_03.txt";
  const BagImportReport r = import_bag(o);
  EXPECT_EQ(r.messages.thermal, 2u);
  EXPECT_EQ(r.messages.lidar, 2u);
  EXPECT_EQ(r.messages.imu, 3u);
  EXPECT_EQ(r.messages.odom, 3u);
  EXPECT_FALSE(std::filesystem::exists(o.out / ".bag-staging"));

  const Scene s = read_scene(o.out);
  const CameraIntrinsics& k = s.config.camera;
  EXPECT_EQ(k.width, 640);
  EXPECT_EQ(k.bit_depth, 8);
  EXPECT_NEAR(k.fx, 435.836, 1e-3);
  EXPECT_NEAR(k.cy, 255.554, 1e-3);
  // T_cam_lidar is the inverse of the file's camera-to-LiDAR extrinsic.
  const M2dgrCamera cam = read_m2dgr_camera(o.calib);
  EXPECT_LT((s.config.T_cam_lidar * cam.T_lidar_cam - Eigen::Matrix4d::Identity()).norm(), 1e-12);
  EXPECT_EQ(s.config.poses_frame, PoseFrame::kImu);
  EXPECT_FALSE(s.config.has_lidar_map);
  ASSERT_EQ(s.frames.size(), 2u);
  EXPECT_EQ(s.frames[1].t_s, 1628410457.15);
  EXPECT_EQ(load_frame(o.out, s, 1).data, thermal(2, 1).data);
  ASSERT_EQ(s.poses.size(), 3u);
  EXPECT_EQ(s.poses[2].p_world, Eigen::Vector3d(2, 0.5, -0.5));
  EXPECT_NEAR(s.poses[1].q_world_body.angularDistance(
                  Eigen::Quaterniond(Eigen::AngleAxisd(0.1, Eigen::Vector3d::UnitZ()))),
              0, 1e-12);
  ASSERT_EQ(s.imu.size(), 3u);
  EXPECT_EQ(s.imu[2].accel_m_s2.z(), -0.4);
  ASSERT_EQ(s.scans.size(), 2u);
  const PointCloud scan = read_pcd(o.out / s.scans[0].file);
  ASSERT_EQ(scan.size(), 2u);  // the NaN return dropped
  EXPECT_EQ(scan.positions[1], Eigen::Vector3d(4.5, -5, 6));
  EXPECT_EQ(scan.intensity[1], 30.f);
  ASSERT_TRUE(s.gt.has_value());
  EXPECT_FALSE(s.gt->poses.front().has_rotation);  // M2DGR's tracker: translation only
}

TEST_F(ImportBagTest, BadBagsAreNamed) {
  BagImportOptions o;
  o.bag = write_bag();
  o.calib = testing::data_dir() / "m2dgr/calibration_results.txt";
  o.out = dir_ / "scene";
  // No odometry topic and no --poses.
  testing::expect_io_error([&] { import_bag(o); }, {"tiny.bag", "no trajectory"});
  // A topic of the wrong type.
  o.topics.thermal = "/handsfree/imu";
  o.topics.imu = "";
  testing::expect_io_error([&] { import_bag(o); }, {"tiny.bag", "/handsfree/imu", "type is sensor_msgs/Imu"});
  // A topic that is not there.
  o.topics.thermal = "/nope";
  testing::expect_io_error([&] { import_bag(o); }, {"tiny.bag", "no message on the thermal topic '/nope'"});
  // Truncated and garbage bags.
  const std::string bytes = read_file_bytes(o.bag);
  o.topics = {};
  for (size_t n : {size_t{0}, size_t{10}, bytes.size() / 2}) {
    std::ofstream(dir_ / "cut.bag", std::ios::binary) << bytes.substr(0, n);
    o.bag = dir_ / "cut.bag";
    testing::expect_io_error([&] { import_bag(o); }, {"cut.bag"});
  }
  EXPECT_FALSE(std::filesystem::exists(o.out / "scene.yaml"));
}

// A PointCloud2 whose field offset is forged to 2^32 - 4 (the issue-12 review): offset + 4 wraps to 0 in
// 32-bit arithmetic, which passed the old "offset + size > point_step" check and read 4 GiB past each point.
// The bag is written by rosbag_storage and the one serialized PointField is patched in place (same length,
// so the bag's records stay consistent).
TEST_F(ImportBagTest, PointCloudFieldOffsetThatWouldWrapIsAnError) {
  PointCloud c;
  c.positions = {{1, 2, 3}, {4, 5, 6}};
  c.intensity = {7, 8};
  {
    RosBagWriter w(dir_ / "cloud.bag");
    w.cloud("/velodyne_points", 100.0, c);
    w.close();
  }
  const std::string good = read_file_bytes(dir_ / "cloud.bag");
  RosBagTopics topics;
  topics.thermal = topics.imu = "";
  size_t points = 0;
  RosBagHandlers h;
  h.lidar = [&](double, PointCloud cloud) { points += cloud.size(); };
  read_ros_bag(dir_ / "cloud.bag", topics, h);
  ASSERT_EQ(points, 2u);  // the unpatched bag reads

  // Serialized sensor_msgs/PointField: string name (uint32 length + bytes), uint32 offset, uint8 datatype
  // (7 = FLOAT32), uint32 count; little-endian.
  for (const auto& [name, offset] : {std::pair<std::string, uint32_t>{"x", 0}, {"z", 8}, {"intensity", 12}}) {
    for (uint32_t forged : {0xFFFFFFFCu, 0xFFFFFFFFu}) {
      std::string field(4, '\0');
      field[0] = static_cast<char>(name.size());
      field += name;
      const auto put_u32 = [](std::string& s, uint32_t v) {
        for (int b = 0; b < 4; ++b) s += static_cast<char>((v >> (8 * b)) & 0xff);
      };
      std::string original = field, patched = field;
      put_u32(original, offset);
      put_u32(patched, forged);
      original += '\x07';
      patched += '\x07';
      const size_t at = good.find(original);
      ASSERT_NE(at, std::string::npos) << name;
      ASSERT_EQ(good.find(original, at + 1), std::string::npos) << name << ": the field must occur once";
      std::string bad = good;
      bad.replace(at, patched.size(), patched);
      std::ofstream(dir_ / "forged.bag", std::ios::binary | std::ios::trunc) << bad;
      testing::expect_io_error(
          [&] { read_ros_bag(dir_ / "forged.bag", topics, h); },
          {"forged.bag", "/velodyne_points", "field '" + name + "'", "beyond point_step 16"});
    }
  }
  EXPECT_EQ(points, 2u);  // no forged message reached the handler
}

// Truncations and byte flips of a valid bag: read_ros_bag reads something or throws IoError, never another
// exception (rosbag_storage's own exceptions are translated).
TEST_F(ImportBagTest, CorruptBagsThrowIoErrorOnly) {
  const std::string good = read_file_bytes(write_bag());
  RosBagTopics topics;
  topics.odom = "/odom";
  std::mt19937 rng(7);
  int other = 0;
  for (int i = 0; i < 120; ++i) {
    std::string m = good;
    if (i % 2 == 0) {
      m.resize(rng() % m.size());
    } else {
      for (int e = 0; e < 4; ++e) m[rng() % m.size()] = static_cast<char>(rng() & 0xff);
    }
    std::ofstream(dir_ / "m.bag", std::ios::binary | std::ios::trunc) << m;
    try {
      read_ros_bag(dir_ / "m.bag", topics, {});
    } catch (const IoError&) {
    } catch (const std::exception& e) {
      if (++other <= 5) ADD_FAILURE() << "mutant " << i << ": non-IoError exception: " << e.what();
    }
  }
}

}  // namespace
}  // namespace litgs::io
