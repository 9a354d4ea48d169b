#include <gtest/gtest.h>

#include <Eigen/Geometry>

#include "io/export_scene.h"
#include "io/image.h"
#include "io/import_livo2.h"
#include "io/pcd.h"
#include "io/scene.h"
#include "io/tum.h"
#include "tests/io/io_test.h"

namespace litgs::io {
namespace {

class ImportLivo2Test : public testing::TempDirTest {
 protected:
  // A synthetic FAST-LIVO2 output with known poses and extrinsics.
  void SetUp() override {
    TempDirTest::SetUp();
    // Camera config in the ROS 1 style (top-level keys), images at half the calibrated size.
    write_text("config/camera.yaml",
               "cam_model: Pinhole\ncam_width: 16\ncam_height: 12\nscale: 0.5\n"
               "cam_fx: 20.5\ncam_fy: 21.0\ncam_cx: 7.75\ncam_cy: 6.25\n"
               "cam_d0: -0.1\ncam_d1: 0.01\ncam_d2: 0.001\ncam_d3: -0.002\n");
    // Main config in the ROS 2 style (nested under ros__parameters). Rcl: camera z = LiDAR x, camera x =
    // -LiDAR y, camera y = -LiDAR z (the usual forward-looking camera), printed with 6 digits as real
    // configs are (|R^T R - I| ~ 1e-6: orthonormalized).
    write_text("config/main.yaml",
               "/fastlivo2_node:\n  ros__parameters:\n    extrin_calib:\n"
               "      extrinsic_T: [0.04165, 0.02326, -0.0284]\n"
               "      extrinsic_R: [0, -1, 0, 1, 0, 0, 0, 0, 1]\n"
               "      Rcl: [0.000001, -1, 0,\n            0, 0, -1,\n            1, 0, 0]\n"
               "      Pcl: [0.0194384, 0.104689, -0.0251952]\n");
    // IMU poses: at 100.0 and 100.2 (yaw 0 and 90 degrees), 100.4.
    imu_.resize(3);
    for (int i = 0; i < 3; ++i) {
      imu_[i].t_s = 100.0 + 0.2 * i;
      imu_[i].p_world = {1.0 * i, 2.0, 0.5 * i};
      imu_[i].q_world_body = Eigen::Quaterniond(Eigen::AngleAxisd(i * M_PI / 4, Eigen::Vector3d::UnitZ()));
    }
    std::filesystem::create_directories(dir_ / "Log/result");
    write_text("Log/result/seq.txt",
               "100.000000 0 2 0 0 0 0 1\n"
               "100.200000 1 2 0.5 0 0 0.38268343236508978 0.92387953251128674\n"
               "100.400000 2 2 1 0 0 0.70710678118654757 0.70710678118654757\n");
    // Two map files (one per batch), merged.
    std::filesystem::create_directories(dir_ / "Log/pcd");
    PointCloud a, b;
    a.positions = {{1, 2, 3}, {4, 5, 6}};
    b.positions = {{-1, -2, -3}};
    write_pcd(dir_ / "Log/pcd/0.pcd", a);
    write_pcd(dir_ / "Log/pcd/1.pcd", b);
    // Frames: at the first pose, between the last two, and after the trajectory; RGB with equal channels.
    std::filesystem::create_directories(dir_ / "Log/image");
    for (const char* t : {"100.000000", "100.300000", "100.500000"}) {
      Image im;
      im.width = 8;
      im.height = 6;
      im.channels = 3;
      for (int i = 0; i < 48; ++i)
        for (int c = 0; c < 3; ++c) im.data.push_back(static_cast<uint16_t>(i * 5));
      write_image(dir_ / "Log/image" / (std::string(t) + ".png"), im);
    }
    o_.log = dir_ / "Log";
    o_.config = {dir_ / "config/camera.yaml", dir_ / "config/main.yaml"};
    o_.out = dir_ / "scene";
  }

  // Where the camera sees world point X, following the sensor chain point by point: world -> IMU (pose),
  // IMU -> LiDAR (inverse of extrinsic_R/T), LiDAR -> camera (Rcl, Pcl).
  static Eigen::Vector3d camera_point(const Eigen::Matrix3d& R_world_imu, const Eigen::Vector3d& p_world_imu,
                                      const Eigen::Vector3d& X) {
    Eigen::Matrix3d R_il, R_cl;
    R_il << 0, -1, 0, 1, 0, 0, 0, 0, 1;
    R_cl << 0, -1, 0, 0, 0, -1, 1, 0, 0;
    const Eigen::Vector3d t_il(0.04165, 0.02326, -0.0284), t_cl(0.0194384, 0.104689, -0.0251952);
    const Eigen::Vector3d x_imu = R_world_imu.transpose() * (X - p_world_imu);
    const Eigen::Vector3d x_lidar = R_il.transpose() * (x_imu - t_il);
    return R_cl * x_lidar + t_cl;
  }

  std::vector<TumPose> imu_;
  Livo2ImportOptions o_;
};

TEST_F(ImportLivo2Test, CameraPosesIntrinsicsAndMap) {
  const Livo2ImportReport r = import_livo2(o_);
  EXPECT_EQ(r.frames, 2u);
  EXPECT_EQ(r.skipped_no_pose, 1u);  // 100.5 is after the last pose
  EXPECT_EQ(r.map_points, 3u);

  const Scene s = read_scene(o_.out);
  const CameraIntrinsics& k = s.config.camera;
  EXPECT_EQ(k.width, 8);
  EXPECT_EQ(k.height, 6);
  EXPECT_EQ(k.fx, 10.25);
  EXPECT_EQ(k.fy, 10.5);
  EXPECT_EQ(k.cx, 3.875);
  EXPECT_EQ(k.cy, 3.125);
  EXPECT_EQ(k.distortion, (std::vector<double>{-0.1, 0.01, 0.001, -0.002}));
  EXPECT_EQ(k.bit_depth, 8);
  EXPECT_EQ(s.config.poses_frame, PoseFrame::kCamera);
  EXPECT_TRUE(s.config.has_lidar_map);
  EXPECT_EQ(s.config.T_imu_lidar(0, 3), 0.04165);
  EXPECT_EQ(s.config.T_cam_lidar(1, 3), 0.104689);
  EXPECT_NEAR(s.config.T_cam_lidar(2, 0), 1.0, 1e-9);

  ASSERT_EQ(s.map->size(), 3u);
  EXPECT_EQ(s.map->positions[2], Eigen::Vector3d(-1, -2, -3));

  ASSERT_EQ(s.frames.size(), 2u);
  EXPECT_EQ(s.frames[0].t_s, 100.0);
  EXPECT_EQ(s.frames[1].t_s, 100.3);
  // Frame 0 at IMU pose 0; frame 1 halfway between poses 1 and 2 (yaw 67.5 degrees).
  const Eigen::Matrix3d R0 = Eigen::Matrix3d::Identity();
  const Eigen::Matrix3d R1 = Eigen::AngleAxisd(3 * M_PI / 8, Eigen::Vector3d::UnitZ()).toRotationMatrix();
  const Eigen::Vector3d p0(0, 2, 0), p1(1.5, 2, 0.75);
  for (const Eigen::Vector3d& X : {Eigen::Vector3d(5, 1, 0.3), Eigen::Vector3d(-2, 7, 1)}) {
    for (int i = 0; i < 2; ++i) {
      const TumPose& pose = s.poses[static_cast<size_t>(i)];
      const Eigen::Vector3d expected = camera_point(i ? R1 : R0, i ? p1 : p0, X);
      const Eigen::Vector3d got = pose.q_world_body.conjugate() * (X - pose.p_world);
      EXPECT_LT((got - expected).norm(), 1e-5) << "frame " << i;  // Rcl printed with 6 digits
    }
  }
  // The camera looks along LiDAR x = IMU +y (extrinsic_R column 0): for yaw 0 that is world +y.
  EXPECT_LT((s.poses[0].q_world_body * Eigen::Vector3d::UnitZ() - Eigen::Vector3d(0, 1, 0)).norm(), 1e-5);

  // The frames arrive as one channel with their values.
  const Image f = load_frame(o_.out, s, 1);
  EXPECT_EQ(f.channels, 1);
  EXPECT_EQ(f.at(3, 2), (2 * 8 + 3) * 5);

  // export tum --camera of the scene gives the same camera poses; export colmap holds both frames.
  TumExportOptions t;
  t.scene = o_.out;
  t.out = dir_ / "cam.tum";
  t.camera = true;
  EXPECT_EQ(export_tum(t), 2u);
  const auto cam = read_tum(t.out);
  EXPECT_LT((cam[1].p_world - s.poses[1].p_world).norm(), 1e-12);
}

TEST_F(ImportLivo2Test, ImuScenePosesExportAsTheSameCameraPoses) {
  // The scene's IMU -> camera conversion (camera_poses_at_frames) agrees with the importer's.
  import_livo2(o_);
  Scene s = read_scene(o_.out);
  const std::vector<TumPose> camera_poses = s.poses;
  s.config.poses_frame = PoseFrame::kImu;
  s.poses = read_tum(dir_ / "Log/result/seq.txt");
  const auto T = camera_poses_at_frames(s);
  ASSERT_EQ(T.size(), 2u);
  for (size_t i = 0; i < 2; ++i) {
    ASSERT_TRUE(T[i].has_value());
    EXPECT_LT((T[i]->topRightCorner<3, 1>() - camera_poses[i].p_world).norm(), 1e-12);
    EXPECT_LT((T[i]->topLeftCorner<3, 3>() - camera_poses[i].q_world_body.toRotationMatrix()).norm(), 1e-12);
  }
}

TEST_F(ImportLivo2Test, PrefersTheDownsampledMapAndNamesBadInput) {
  PointCloud all;
  all.positions = {{9, 9, 9}};
  write_pcd(dir_ / "Log/pcd/all_downsampled_points.pcd", all);
  EXPECT_EQ(import_livo2(o_).map_points, 1u);

  o_.out = dir_ / "scene2";
  write_text("config/camera.yaml", "cam_model: EquidistantCamera\ncam_width: 16\n");
  testing::expect_io_error([&] { import_livo2(o_); }, {"camera.yaml:1:", "cam_model 'EquidistantCamera'"});
  write_text("config/camera.yaml", "cam_model: Pinhole\ncam_width: 16\ncam_height: 12\ncam_fy: 1\n");
  testing::expect_io_error([&] { import_livo2(o_); }, {"camera.yaml", "key 'cam_fx' not found"});
  write_text("config/camera.yaml",
             "cam_model: Pinhole\ncam_width: 8\ncam_height: 6\ncam_fx: 1\ncam_fy: 1\ncam_cx: 1\ncam_cy: 1\n");
  write_text("config/main.yaml",
             "extrinsic_T: [0, 0, 0]\nextrinsic_R: [1, 0, 0, 0, 1, 0, 0, 0, 1]\n"
             "Rcl: [1, 0, 0, 0, 1, 0, 0, 0.5, 1]\nPcl: [0, 0, 0]\n");
  testing::expect_io_error([&] { import_livo2(o_); }, {"main.yaml:3:", "Rcl is not a rotation"});
  write_text(
      "config/main.yaml",
      "extrinsic_T: [0, 0]\nextrinsic_R: [1, 0, 0, 0, 1, 0, 0, 0, 1]\nRcl: [1, 0, 0, 0, 1, 0, 0, 0, 1]\n"
      "Pcl: [0, 0, 0]\n");
  testing::expect_io_error([&] { import_livo2(o_); }, {"main.yaml:1:", "extrinsic_T: expected a list of 3"});
  write_text(
      "config/main.yaml",
      "extrinsic_T: [0, 0, 0]\nextrinsic_R: [1, 0, 0, 0, 1, 0, 0, 0, 1]\nRcl: [1, 0, 0, 0, 1, 0, 0, 0, 1]\n"
      "Pcl: [0, 0, 0]\n");
  write_text("Log/result/seq.txt", "100 0 0 0 0 0 0 1\n99 0 0 0 0 0 0 1\n");
  testing::expect_io_error([&] { import_livo2(o_); }, {"seq.txt:2:", "not greater"});
  write_text("Log/result/seq.txt", "200 0 0 0 0 0 0 1\n201 0 0 0 0 0 0 1\n");
  testing::expect_io_error([&] { import_livo2(o_); }, {"image", "no frame lies within the trajectory"});
  write_text("Log/result/other.txt", "");
  testing::expect_io_error([&] { import_livo2(o_); }, {"result", "2 .txt files"});
  EXPECT_FALSE(std::filesystem::exists(o_.out / "scene.yaml"));
}

}  // namespace
}  // namespace litgs::io
