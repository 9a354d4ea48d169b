#include <gtest/gtest.h>

#include <fstream>

#include "io/file_bytes.h"
#include "io/pcd.h"
#include "io/scene.h"
#include "tests/io/io_test.h"

namespace litgs::io {
namespace {

class SceneTest : public testing::TempDirTest {
 protected:
  // A small scene with every optional part, values chosen to need full double precision.
  static Scene full_scene() {
    Scene s;
    SceneConfig& c = s.config;
    c.camera.model = CameraModel::kPinhole;
    c.camera.width = 16;
    c.camera.height = 12;
    c.camera.fx = 435.836180277211;
    c.camera.fy = 435.909430631362;
    c.camera.cx = 7.5 + 1.0 / 3.0;
    c.camera.cy = 5.25;
    c.camera.distortion = {-0.436107594318055, 0.166413618922992, 1e-5, -2e-5};
    c.camera.bit_depth = 16;
    c.T_cam_lidar << 0, -1, 0, 0.17065, 0, 0, -1, 0.65376, 1, 0, 0, -0.30456, 0, 0, 0, 1;
    c.T_imu_lidar.topRightCorner<3, 1>() = Eigen::Vector3d(-0.27255, 0.00053, -0.17954);
    c.time_offset_cam_lidar_s = -0.0123;
    c.lidar_holdout_every = 8;
    c.intensity_window = std::make_pair(3620.5, 4618.0);
    c.poses_frame = PoseFrame::kImu;
    c.world_offset_m = {999.59453537619925, 1002.8533203485084, 101.14485388253293};
    c.source = "unit test \"full\" scene";
    for (double t : {0.1, 0.2, 1628410457.03}) s.frames.push_back({t, frame_file_name(t)});
    for (int i = 0; i < 3; ++i) {
      TumPose p;
      p.t_s = s.frames[i].t_s;
      p.p_world = {i / 3.0, -i * 0.7, 1e-3 * i};
      p.q_world_body =
          Eigen::Quaterniond(Eigen::AngleAxisd(0.1 * i + 0.05, Eigen::Vector3d(1, 2, 3).normalized()));
      s.poses.push_back(p);
    }
    PointCloud map;
    map.positions = {{1000.123456789, 2.5, -3.25}, {0.1, 0.2, 0.3}};
    map.intensity = {3.5f, 100.f};
    s.map = map;
    s.scans = {{0.15, {}}, {0.25, {}}};
    s.imu = {{0.1, {0.01, -0.02, 0.03}, {0.1, 9.81, -0.2}}, {0.1 + 1.0 / 150, {0, 0, 0}, {0, 9.8, 0}}};
    Anchor a;
    a.p_world = {1.0 / 7.0, 2, 3};
    a.cov_m2 << 1e-6, 1e-8, 0, 1e-8, 2e-6, -1e-9, 0, -1e-9, 3e-6;
    s.anchors = {a, Anchor{}};
    GroundTruth gt;
    gt.poses = s.poses;
    gt.poses[1].has_rotation = false;
    gt.map = map;
    gt.planes = {{Eigen::Vector3d(0, 1, 0), -1009.5}, {Eigen::Vector3d(0.6, 0.8, 0), 1.0 / 3.0}};
    s.gt = gt;
    return s;
  }

  static Image frame_image(const Scene& s, size_t i) {
    Image im;
    im.width = s.config.camera.width;
    im.height = s.config.camera.height;
    im.bit_depth = s.config.camera.bit_depth;
    for (int k = 0; k < im.width * im.height; ++k)
      im.data.push_back(static_cast<uint16_t>(3000 + 97 * static_cast<size_t>(k) + 1000 * i));
    return im;
  }

  static PointCloud scan_cloud(size_t i) {
    PointCloud c;
    c.positions = {{1.0 + static_cast<double>(i), 2, 3}, {-4, 5.5, 6}};
    return c;
  }

  void write(const Scene& s) {
    write_scene(
        dir_, s, [&](size_t i) { return frame_image(s, i); }, scan_cloud);
  }
};

void expect_same_poses(const std::vector<TumPose>& a, const std::vector<TumPose>& b) {
  ASSERT_EQ(a.size(), b.size());
  for (size_t i = 0; i < a.size(); ++i) {
    EXPECT_EQ(a[i].t_s, b[i].t_s);
    EXPECT_EQ(a[i].p_world, b[i].p_world);
    EXPECT_EQ(a[i].has_rotation, b[i].has_rotation);
    if (a[i].has_rotation) {
      EXPECT_LT((a[i].q_world_body.coeffs() - b[i].q_world_body.coeffs()).norm(), 1e-15);
    }
  }
}

TEST_F(SceneTest, RoundTripKeepsEverything) {
  const Scene s = full_scene();
  write(s);
  const Scene r = read_scene(dir_);
  const SceneConfig &a = s.config, &b = r.config;
  EXPECT_EQ(b.camera.model, a.camera.model);
  EXPECT_EQ(b.camera.width, a.camera.width);
  EXPECT_EQ(b.camera.height, a.camera.height);
  EXPECT_EQ(b.camera.fx, a.camera.fx);
  EXPECT_EQ(b.camera.fy, a.camera.fy);
  EXPECT_EQ(b.camera.cx, a.camera.cx);
  EXPECT_EQ(b.camera.cy, a.camera.cy);
  EXPECT_EQ(b.camera.distortion, a.camera.distortion);
  EXPECT_EQ(b.camera.bit_depth, a.camera.bit_depth);
  EXPECT_EQ(b.T_cam_lidar, a.T_cam_lidar);
  EXPECT_EQ(b.T_imu_lidar, a.T_imu_lidar);
  EXPECT_EQ(b.time_offset_cam_lidar_s, a.time_offset_cam_lidar_s);
  EXPECT_EQ(b.poses_frame, a.poses_frame);
  EXPECT_EQ(b.has_lidar_map, a.has_lidar_map);
  EXPECT_EQ(b.lidar_holdout_every, a.lidar_holdout_every);
  EXPECT_EQ(b.world_offset_m, a.world_offset_m);
  EXPECT_EQ(b.intensity_window, a.intensity_window);
  EXPECT_EQ(b.source, a.source);
  ASSERT_EQ(r.frames.size(), 3u);
  for (size_t i = 0; i < 3; ++i) {
    EXPECT_EQ(r.frames[i].t_s, s.frames[i].t_s);
    EXPECT_EQ(r.frames[i].image, s.frames[i].image);
    EXPECT_EQ(load_frame(dir_, r, i).data, frame_image(s, i).data);
  }
  expect_same_poses(r.poses, s.poses);
  ASSERT_TRUE(r.map.has_value());
  EXPECT_EQ(r.map->positions, s.map->positions);
  EXPECT_EQ(r.map->intensity, s.map->intensity);
  ASSERT_EQ(r.scans.size(), 2u);
  EXPECT_EQ(r.scans[1].t_s, 0.25);
  EXPECT_EQ(read_pcd(dir_ / r.scans[1].file).positions, scan_cloud(1).positions);
  ASSERT_EQ(r.imu.size(), 2u);
  EXPECT_EQ(r.imu[1].t_s, s.imu[1].t_s);
  EXPECT_EQ(r.imu[0].gyro_rad_s, s.imu[0].gyro_rad_s);
  EXPECT_EQ(r.imu[0].accel_m_s2, s.imu[0].accel_m_s2);
  ASSERT_EQ(r.anchors.size(), 2u);
  EXPECT_EQ(r.anchors[0].p_world, s.anchors[0].p_world);
  EXPECT_EQ(r.anchors[0].cov_m2, s.anchors[0].cov_m2);
  ASSERT_TRUE(r.gt.has_value());
  expect_same_poses(r.gt->poses, s.gt->poses);
  EXPECT_EQ(r.gt->map->positions, s.gt->map->positions);
  ASSERT_EQ(r.gt->planes.size(), 2u);
  EXPECT_EQ(r.gt->planes[1].n, s.gt->planes[1].n);
  EXPECT_EQ(r.gt->planes[1].d, s.gt->planes[1].d);
}

TEST_F(SceneTest, MinimalSceneWithoutLidarMap) {
  Scene s = full_scene();
  s.config.has_lidar_map = false;
  s.map.reset();
  s.scans.clear();
  s.imu.clear();
  s.anchors.clear();
  s.gt.reset();
  write(s);
  const Scene r = read_scene(dir_);
  EXPECT_FALSE(r.config.has_lidar_map);
  EXPECT_FALSE(r.map.has_value());
  EXPECT_FALSE(r.gt.has_value());
  EXPECT_TRUE(r.imu.empty());
  // A map file that scene.yaml does not announce is an inconsistency.
  write_text("lidar/map.pcd", "");
  testing::expect_io_error([&] { read_scene(dir_); }, {"map.pcd", "lidar_map: false"});
}

TEST_F(SceneTest, MissingFilesAreNamed) {
  write(full_scene());
  std::filesystem::remove(dir_ / "poses.txt");
  testing::expect_io_error([&] { read_scene(dir_); }, {"poses.txt", "missing"});
  write(full_scene());
  std::filesystem::remove(dir_ / "lidar/map.pcd");
  testing::expect_io_error([&] { read_scene(dir_); }, {"map.pcd", "missing", "lidar_map: true"});
  std::filesystem::remove(dir_ / "scene.yaml");
  testing::expect_io_error([&] { read_scene(dir_); }, {"scene.yaml", "does not exist"});
}

TEST_F(SceneTest, ImageOfTheWrongSizeIsNamed) {
  const Scene s = full_scene();
  write(s);
  Image small = frame_image(s, 0);
  small.width = 15;
  small.data.resize(15 * 12);
  write_image(dir_ / "thermal/0.3.png", small);
  testing::expect_io_error([&] { read_scene(dir_); },
                           {"0.3.png", "image is 15x12, scene.yaml camera is 16x12"});
  std::filesystem::remove(dir_ / "thermal/0.3.png");
  write_text("thermal/frame1.png", "");
  testing::expect_io_error([&] { read_scene(dir_); }, {"frame1.png", "not a timestamp"});
}

TEST_F(SceneTest, BadTextFilesNameFileAndLine) {
  write(full_scene());
  write_text("anchors.txt", "1 2 3 1 0 0 1 0 1\n1 2 3 1 0 0 1 0\n");
  testing::expect_io_error([&] { read_scene(dir_); }, {"anchors.txt:2:", "expected 9 fields"});
  write_text("anchors.txt", "# x y z cov\n1 2 3 1 0 0 1 0 1\n1 2 3 1 2 0 1 0 1\n");
  testing::expect_io_error([&] { read_scene(dir_); }, {"anchors.txt:3:", "not positive definite"});
  write_text("anchors.txt", "1 2 3 0 0 0 0 0 0\n");
  testing::expect_io_error([&] { read_scene(dir_); }, {"anchors.txt:1:", "not positive definite"});
  std::filesystem::remove(dir_ / "anchors.txt");
  write_text("imu.csv",
             "t,gyro_x,gyro_y,gyro_z,accel_x,accel_y,accel_z\n1,0,0,0,0,0,9.8\n0.5,0,0,0,0,0,9.8\n");
  testing::expect_io_error([&] { read_scene(dir_); }, {"imu.csv:3:", "not greater than the previous 1"});
  write_text("imu.csv", "t,gyro_x,gyro_y,gyro_z,accel_x,accel_y,accel_z\n1,0,0,inf,0,0,9.8\n");
  testing::expect_io_error([&] { read_scene(dir_); }, {"imu.csv:2:", "gyro_z", "non-finite"});
  std::filesystem::remove(dir_ / "imu.csv");
  write_text("poses.txt", "0.1 0 0 0 0 0 0 1\n0.2 0 NaN 0 0 0 0 1\n");
  testing::expect_io_error([&] { read_scene(dir_); }, {"poses.txt:2:", "y", "non-finite"});
  write_text("poses.txt", "0.1 0 0 0 0 0 0 1\n");
  write_text("gt/planes.txt", "0 0 2 1\n");
  testing::expect_io_error([&] { read_scene(dir_); }, {"planes.txt:1:", "normal length is 2"});
}

TEST_F(SceneTest, BadSceneYamlNamesTheLine) {
  write(full_scene());
  const std::string good = read_file_bytes(dir_ / "scene.yaml");
  const auto replace = [&](const std::string& from, const std::string& to) {
    std::string s = good;
    const size_t p = s.find(from);
    EXPECT_NE(p, std::string::npos) << from;
    s.replace(p, from.size(), to);
    write_text("scene.yaml", s);
  };
  replace("  width: 16", "  widht: 16");
  testing::expect_io_error([&] { read_scene(dir_); }, {"scene.yaml:7:", "unknown key 'camera.widht'"});
  replace("  bit_depth: 16", "  bit_depth: 12");
  testing::expect_io_error([&] { read_scene(dir_); }, {"scene.yaml", "bit_depth: must be 8 or 16"});
  replace("poses_frame: imu", "poses_frame: body");
  testing::expect_io_error([&] { read_scene(dir_); }, {"scene.yaml:", "'body' is not camera or imu"});
  replace("  - [0, -1, 0, 0.17065]", "  - [0, -2, 0, 0.17065]");
  testing::expect_io_error([&] { read_scene(dir_); },
                           {"scene.yaml:", "T_cam_lidar is not a rigid transform"});
  replace("time_offset_cam_lidar_s: -0.0123", "time_offset_cam_lidar_s: .nan");
  testing::expect_io_error([&] { read_scene(dir_); },
                           {"scene.yaml:25:", "time_offset_cam_lidar_s", "non-finite"});
  replace("intensity_window: [3620.5, 4618]", "intensity_window: [4618, 3620.5]");
  testing::expect_io_error([&] { read_scene(dir_); },
                           {"scene.yaml", "intensity_window: must be", "low < high"});
  replace("intensity_window: [3620.5, 4618]", "intensity_window: [3620.5]");
  testing::expect_io_error([&] { read_scene(dir_); },
                           {"scene.yaml:", "intensity_window: expected [low, high]"});
  replace("units: {length: m,", "units: {length: mm,");
  testing::expect_io_error([&] { read_scene(dir_); }, {"scene.yaml:4:", "only 'm'"});
  replace("camera:\n", "camera: [\n");
  testing::expect_io_error([&] { read_scene(dir_); }, {"scene.yaml:", "YAML syntax"});
  // Found by the mutation test: a key that is not a plain name made yaml-cpp throw its own exception.
  write_text("scene.yaml", "format: litgs-scene\n[a, b]: 1\n");
  testing::expect_io_error([&] { read_scene(dir_); }, {"scene.yaml:2:", "not a plain name"});
  write_text("scene.yaml", "just text\n");
  testing::expect_io_error([&] { read_scene(dir_); }, {"scene.yaml:1:", "must be a mapping"});
  write_text("scene.yaml", good);
  EXPECT_NO_THROW(read_scene(dir_));
}

TEST_F(SceneTest, FailedWriteLosesNothing) {
  const Scene s = full_scene();
  write(s);
  const std::string yaml = read_file_bytes(dir_ / "scene.yaml");
  const std::string poses = read_file_bytes(dir_ / "poses.txt");
  Scene t = s;
  t.config.source = "second write";
  EXPECT_THROW(write_scene(
                   dir_, t,
                   [&](size_t i) {
                     Image im = frame_image(s, i);
                     if (i == 2) im.bit_depth = 8, im.data.assign(im.data.size(), 1);
                     return im;
                   },
                   scan_cloud),
               std::invalid_argument);
  EXPECT_EQ(read_file_bytes(dir_ / "scene.yaml"), yaml);
  EXPECT_EQ(read_file_bytes(dir_ / "poses.txt"), poses);
  EXPECT_EQ(read_scene(dir_).config.source, s.config.source);
  size_t files = 0;
  for (const auto& e : std::filesystem::recursive_directory_iterator(dir_))
    if (e.path().string().find(".tmp-") != std::string::npos) ++files;
  EXPECT_EQ(files, 0u) << "temporary files left behind";
}

}  // namespace
}  // namespace litgs::io
