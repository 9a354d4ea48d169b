#include <gtest/gtest.h>

#include <Eigen/Geometry>
#include <algorithm>
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
    if (!ros_bag_writer_available()) GTEST_FAIL() << "this build cannot write ROS bags (ci/setup)";
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
  static std::string u32le(uint32_t v) {
    std::string s;
    for (int b = 0; b < 4; ++b) s += static_cast<char>((v >> (8 * b)) & 0xff);
    return s;
  }
  // `bytes` with the one occurrence of `from` replaced by `to` (same length, so the bag's records stay
  // consistent); fails the test unless `from` occurs exactly once.
  static std::string patch_once(const std::string& bytes, const std::string& from, const std::string& to) {
    EXPECT_EQ(from.size(), to.size());
    const size_t at = bytes.find(from);
    if (at == std::string::npos || bytes.find(from, at + 1) != std::string::npos) {
      ADD_FAILURE() << "the patched bytes must occur exactly once";
      return bytes;
    }
    std::string out = bytes;
    out.replace(at, to.size(), to);
    return out;
  }
  std::filesystem::path write_bytes(const std::string& name, const std::string& bytes) const {
    std::ofstream(dir_ / name, std::ios::binary | std::ios::trunc) << bytes;
    return dir_ / name;
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
  // T_imu_lidar from the block of the IMU topic (/handsfree/imu): the IMU 0.27 m behind and 0.18 m below.
  const M2dgrCamera imu = read_m2dgr_camera(o.calib, "Handsfree IMU");
  EXPECT_LT((s.config.T_imu_lidar * imu.T_lidar_cam - Eigen::Matrix4d::Identity()).norm(), 1e-12);
  EXPECT_NEAR(s.config.T_imu_lidar(0, 3), 0.27255, 1e-12);
  EXPECT_NE(std::find_if(r.notes.begin(), r.notes.end(),
                         [](const std::string& n) { return n.find("'Handsfree IMU'") != std::string::npos; }),
            r.notes.end());
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

TEST(ImportBagImuBlock, TheImuTopicPicksTheCalibrationBlock) {
  EXPECT_EQ(m2dgr_imu_block("/handsfree/imu"), "Handsfree IMU");
  EXPECT_EQ(m2dgr_imu_block("/camera/imu"), "realsense d435i IMU");
  EXPECT_EQ(m2dgr_imu_block("/imu/data"), "Xsens IMU");
  EXPECT_EQ(m2dgr_imu_block("/dvs/imu"), "");
  // Each block reads: the realsense block is a rotation as well as a 0.7 m lever arm.
  for (const char* block : {"Handsfree IMU", "realsense d435i IMU", "Xsens IMU"}) {
    const M2dgrCamera b = read_m2dgr_camera(testing::data_dir() / "m2dgr/calibration_results.txt", block);
    EXPECT_TRUE(b.has_extrinsic) << block;
    const Eigen::Vector3d lever = b.T_lidar_cam.topRightCorner<3, 1>();
    EXPECT_GT(lever.norm(), 0.2) << block;
  }
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
TEST_F(ImportBagTest, PerPointTimeFieldIsKeptForDeskewing) {
  PointCloud c;
  c.positions = {{1, 2, 3}, {4, 5, 6}, {7, 8, 9}};
  c.extra.push_back({"time", {0.0, 0.025, 0.0999}});
  {
    RosBagWriter w(dir_ / "timed.bag");
    w.cloud("/velodyne_points", 100.0, c);
    w.close();
  }
  RosBagTopics topics;
  topics.thermal = topics.imu = "";
  std::vector<double> times;
  RosBagHandlers h;
  h.lidar = [&](double, PointCloud cloud) {
    ASSERT_NE(cloud.field("time"), nullptr);
    times = cloud.field("time")->values;
  };
  read_ros_bag(dir_ / "timed.bag", topics, h);
  ASSERT_EQ(times.size(), 3u);
  for (size_t i = 0; i < 3; ++i) EXPECT_NEAR(times[i], c.extra[0].values[i], 1e-7);  // float32 on the wire
}

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
      const std::string field = u32le(static_cast<uint32_t>(name.size())) + name;
      const auto bag = write_bytes(
          "forged.bag", patch_once(good, field + u32le(offset) + '\x07', field + u32le(forged) + '\x07'));
      testing::expect_io_error(
          [&] { read_ros_bag(bag, topics, h); },
          {"forged.bag", "/velodyne_points", "field '" + name + "'", "beyond point_step 16"});
    }
  }
  EXPECT_EQ(points, 2u);  // no forged message reached the handler
}

// The reader (ros_bag_read.cc, our own parser) against the writer (rosbag_storage): every message type, with
// uncompressed, bz2 and lz4 chunks, comes back as written and in time order (written out of order; two
// 640x512x3 frames make the bag span several chunks).
TEST_F(ImportBagTest, EveryMessageTypeAndCompressionReadsAsWritten) {
  Image mono16;
  mono16.width = 3;
  mono16.height = 2;
  mono16.bit_depth = 16;
  mono16.data = {0, 1, 255, 256, 40000, 65535};
  PointCloud cloud;  // float32-exact positions
  cloud.positions = {{1.5, -2.25, 3}, {NAN, 0, 0}, {1024, 0.125, -7}};
  cloud.intensity = {1, 2, 3};
  const ImuSample imu{11.5, {0.25, -0.5, 1.0 / 3}, {0.1, 9.81, -0.2}};
  TumPose odom;
  odom.t_s = 12.0;
  odom.p_world = {1.0 / 7, -2, 1e3};
  odom.q_world_body = Eigen::Quaterniond(Eigen::AngleAxisd(0.3, Eigen::Vector3d(1, 2, 3).normalized()));
  const std::vector<double> expected_times = {10.5, 11.0, 11.5, 12.0, 13.0, 14.0};

  for (auto compression : {RosBagCompression::kNone, RosBagCompression::kBz2, RosBagCompression::kLz4}) {
    SCOPED_TRACE(static_cast<int>(compression));
    const auto path = dir_ / "all.bag";
    {
      RosBagWriter w(path, compression);
      w.odom("/o", odom);
      w.image("/t", 13.0, thermal(1, 3));
      w.image("/t", 11.0, mono16);
      w.cloud("/l", 10.5, cloud);
      w.image("/t", 14.0, thermal(2, 3));
      w.imu("/i", imu);
      w.close();
    }
    RosBagTopics topics{"/t", "/l", "/i", "/o"};
    std::vector<double> times;
    std::vector<Image> images;
    std::vector<PointCloud> clouds;
    std::vector<ImuSample> imus;
    std::vector<TumPose> poses;
    RosBagHandlers h;
    h.thermal = [&](double t, Image im) { times.push_back(t), images.push_back(std::move(im)); };
    h.lidar = [&](double t, PointCloud c) { times.push_back(t), clouds.push_back(std::move(c)); };
    h.imu = [&](const ImuSample& x) { times.push_back(x.t_s), imus.push_back(x); };
    h.odom = [&](const TumPose& x) { times.push_back(x.t_s), poses.push_back(x); };
    const RosBagCounts n = read_ros_bag(path, topics, h);
    EXPECT_EQ(n.thermal, 3u);
    EXPECT_EQ(n.lidar, 1u);
    EXPECT_EQ(n.imu, 1u);
    EXPECT_EQ(n.odom, 1u);
    EXPECT_EQ(times, expected_times);
    ASSERT_EQ(images.size(), 3u);
    EXPECT_EQ(images[0].bit_depth, 16);
    EXPECT_EQ(images[0].channels, 1);
    EXPECT_EQ(images[0].data, mono16.data);
    EXPECT_EQ(images[1].channels, 3);
    EXPECT_EQ(images[1].data, thermal(1, 3).data);
    EXPECT_EQ(images[2].data, thermal(2, 3).data);
    ASSERT_EQ(clouds.size(), 1u);
    ASSERT_EQ(clouds[0].size(), 2u);  // the NaN point dropped
    EXPECT_EQ(clouds[0].positions[0], cloud.positions[0]);
    EXPECT_EQ(clouds[0].positions[1], cloud.positions[2]);
    EXPECT_EQ(clouds[0].intensity, std::vector<float>({1, 3}));
    ASSERT_EQ(imus.size(), 1u);
    EXPECT_EQ(imus[0].gyro_rad_s, imu.gyro_rad_s);
    EXPECT_EQ(imus[0].accel_m_s2, imu.accel_m_s2);
    ASSERT_EQ(poses.size(), 1u);
    EXPECT_EQ(poses[0].p_world, odom.p_world);
    EXPECT_LT(poses[0].q_world_body.angularDistance(odom.q_world_body), 1e-12);
  }
}

// Lengths and offsets that rosbag_storage and roscpp_serialization trusted (a vector resized to a forged
// length before its bytes were checked; a record read wherever an index entry pointed) are errors that name
// what is wrong, before anything is allocated or read out of bounds.
TEST_F(ImportBagTest, ForgedLengthsAndOffsetsAreErrors) {
  PointCloud c;
  c.positions = {{1, 2, 3}, {4, 5, 6}};
  {
    RosBagWriter w(dir_ / "cloud.bag");
    w.cloud("/velodyne_points", 100.5, c);  // stamp: 100 s + 500000000 ns
    w.close();
  }
  const std::string good = read_file_bytes(dir_ / "cloud.bag");
  RosBagTopics topics;
  topics.thermal = topics.imu = "";
  RosBagHandlers h;
  size_t delivered = 0;
  h.lidar = [&](double, PointCloud) { ++delivered; };
  ASSERT_EQ(read_ros_bag(dir_ / "cloud.bag", topics, h).lidar, 1u);
  ASSERT_EQ(delivered, 1u);
  const auto expect_error = [&](const std::string& bytes, std::initializer_list<std::string> parts) {
    const auto bag = write_bytes("forged.bag", bytes);
    testing::expect_io_error([&] { read_ros_bag(bag, topics, h); }, parts);
  };

  // The message: ... height 1, width 2, 3 fields, "x" ...; point_step 12, row_step 24, data of 24 bytes.
  const std::string fields = u32le(1) + u32le(2) + u32le(3) + u32le(1) + "x";
  expect_error(patch_once(good, fields, u32le(1) + u32le(2) + u32le(0xFFFFFFFF) + u32le(1) + "x"),
               {"/velodyne_points", "ends inside fields"});
  const std::string steps = u32le(12) + u32le(24) + u32le(24);
  expect_error(patch_once(good, steps, u32le(12) + u32le(24) + u32le(0xFFFFFFF0)), {"ends inside data"});
  expect_error(patch_once(good, steps, u32le(12) + u32le(12) + u32le(24)), {"row_step < width * point_step"});
  // The index entry after the chunk: data length 12 (one entry), time (sec, nsec), offset in the chunk.
  const std::string entry = u32le(12) + u32le(100) + u32le(500000000);
  const size_t at = good.find(entry);
  ASSERT_NE(at, std::string::npos);
  ASSERT_EQ(good.find(entry, at + 1), std::string::npos);
  const std::string offset = good.substr(at + entry.size(), 4);
  const uint32_t off = static_cast<uint8_t>(offset[0]) | static_cast<uint8_t>(offset[1]) << 8 |
                       static_cast<uint8_t>(offset[2]) << 16 |
                       static_cast<uint32_t>(static_cast<uint8_t>(offset[3])) << 24;
  expect_error(patch_once(good, entry + offset, entry + u32le(0xFFFFFF00)),
               {"index entry 0 points at byte 4294967040 of a chunk of"});
  // Misaligned into the message record: whatever it reads there is checked against the chunk.
  for (uint32_t d : {1u, 5u, 9u})
    expect_error(patch_once(good, entry + offset, entry + u32le(off + d)), {"chunk at byte"});
  // The header record's index position: 0 is an unfinished recording.
  expect_error(patch_once(good, std::string("index_pos=") + good.substr(good.find("index_pos=") + 10, 8),
                          std::string("index_pos=") + std::string(8, '\0')),
               {"not indexed"});
  // Another definition of the type (its MD5 in both connection records).
  std::string md5 = good;
  for (size_t p = 0; (p = md5.find("1158d486dd51d683ce2f1be655c3c181", p)) != std::string::npos;)
    md5.replace(p, 32, std::string(32, '0'));
  expect_error(md5, {"definition MD5 00000000000000000000000000000000"});
  expect_error("#ROSBAG V1.2\n" + good.substr(13), {"V1.2", "not supported"});
  EXPECT_EQ(delivered, 1u);  // none of the forged messages reached the handler
}

// Truncations and byte flips of a valid bag: read_ros_bag reads something or throws IoError, never another
// exception (every length and offset is checked).
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

namespace litgs::io {
namespace {

// A recording cut short (the recorder killed: the last chunk unfinished, no index) is refused with a pointer
// to --reindex; with it, every complete chunk's messages are read, in time order, and what was lost is said.
// An intact bag reads the same with and without the index.
TEST_F(ImportBagTest, ABagCutShortIsReadToItsLastCompleteChunkWithReindex) {
  for (auto compression : {RosBagCompression::kNone, RosBagCompression::kLz4}) {
    SCOPED_TRACE(static_cast<int>(compression));
    const auto path = dir_ / "long.bag";
    std::vector<double> written;
    {
      RosBagWriter w(path, compression);
      for (int i = 0; i < 6; ++i) {  // two 640x512 frames fill one of rosbag's 768 KiB chunks
        written.push_back(100.0 + 0.1 * i);
        w.image("/thermal_image_raw", written.back(), thermal(i, 1));
        w.imu("/handsfree/imu", {written.back() + 0.01, {0, 0, 0.1}, {0, 0, 9.81}});
      }
      w.close();
    }
    RosBagTopics topics;
    std::vector<double> times;
    RosBagHandlers h;
    h.thermal = [&](double t, Image) { times.push_back(t); };
    const RosBagCounts intact = read_ros_bag(path, topics, h, {.reindex = true});
    EXPECT_EQ(times, written);
    EXPECT_EQ(intact.imu, 6u);
    EXPECT_TRUE(intact.recovery.used);
    EXPECT_EQ(intact.recovery.unread_bytes, 0u);
    EXPECT_GE(intact.recovery.chunks, 3u);

    const std::string bytes = read_file_bytes(path);
    const auto cut = write_bytes("cut.bag", bytes.substr(0, bytes.size() * 7 / 10));
    times.clear();
    try {
      read_ros_bag(cut, topics, h);
      ADD_FAILURE() << "a bag cut short was read through its index";
    } catch (const IoError& e) {
      EXPECT_NE(std::string(e.what()).find("--reindex"), std::string::npos) << e.what();
    }
    times.clear();
    const RosBagCounts recovered = read_ros_bag(cut, topics, h, {.reindex = true});
    ASSERT_GT(times.size(), 0u);
    ASSERT_LT(times.size(), written.size());
    EXPECT_EQ(times, std::vector<double>(written.begin(), written.begin() + static_cast<long>(times.size())));
    EXPECT_GT(recovered.recovery.unread_bytes, 0u);
    EXPECT_FALSE(recovered.recovery.stopped_at.empty());
  }
}

}  // namespace
}  // namespace litgs::io
