// Synthetic scenes through a real rig (synth --rig, M2DGR's calibration file) and out as a bag: the
// rendered depth agrees with OpenCV's projection through the file's lens distortion, and `export bag` then
// `import bag` with the same file gives back the scene's frames, scans, extrinsics and camera poses.
#include <gtest/gtest.h>
#include <unistd.h>

#include <Eigen/Geometry>
#include <cmath>
#include <opencv2/calib3d.hpp>
#include <optional>
#include <vector>

#include "host/synth/synth.h"
#include "io/export_bag.h"
#include "io/export_scene.h"
#include "io/image.h"
#include "io/import_bag.h"
#include "io/m2dgr_calib.h"
#include "io/pcd.h"
#include "io/scene.h"

namespace litgs::host::synth {
namespace {
namespace fs = std::filesystem;

const fs::path kCalib = fs::path(LITGS_TEST_DATA_DIR) / "m2dgr/calibration_results.txt";

class SynthRigTest : public ::testing::Test {
 protected:
  void SetUp() override {
    const auto* info = ::testing::UnitTest::GetInstance()->current_test_info();
    dir_ = fs::temp_directory_path() /
           (std::string("litgs-rig-") + info->name() + "-" + std::to_string(::getpid()));
    fs::remove_all(dir_);
    fs::create_directories(dir_);
  }
  void TearDown() override { fs::remove_all(dir_); }

  // The file's camera, scaled to width x height where given.
  SynthOptions rigged(std::optional<int> width = std::nullopt,
                      std::optional<int> height = std::nullopt) const {
    SynthOptions o;
    o.preset = "facade";
    o.seed = 3;
    o.frames = 10;
    o.width = width;
    o.height = height;
    o.rig = kCalib;
    o.out = dir_ / "synth";
    o.threads = 2;
    return o;
  }

  fs::path dir_;
};

Eigen::Matrix4d inverse(const Eigen::Matrix4d& T) {
  return Eigen::Isometry3d(T).inverse().matrix();
}

Eigen::Matrix4d matrix(const io::TumPose& p) {
  Eigen::Matrix4d T = Eigen::Matrix4d::Identity();
  T.topLeftCorner<3, 3>() = p.q_world_body.toRotationMatrix();
  T.topRightCorner<3, 1>() = p.p_world;
  return T;
}

TEST_F(SynthRigTest, TheRigIsTheFilesAndTheDepthFollowsItsLens) {
  const SynthOptions o = rigged(320, 256);  // half of the file's 640 x 512
  generate_synthetic_scene(o);
  const io::Scene s = io::read_scene(o.out);
  const io::M2dgrCamera cam = io::read_m2dgr_camera(kCalib, "Cam-thermal");
  const io::M2dgrCamera imu = io::read_m2dgr_camera(kCalib, "Handsfree IMU");
  const io::CameraIntrinsics& K = s.config.camera;
  EXPECT_NEAR(K.fx, cam.fx / 2, 1e-9);
  EXPECT_NEAR(K.cy, (cam.cy + 0.5) / 2 - 0.5, 1e-9);
  EXPECT_EQ(K.distortion, cam.distortion);
  EXPECT_TRUE(s.config.T_cam_lidar.isApprox(inverse(cam.T_lidar_cam), 1e-12));
  EXPECT_TRUE(s.config.T_imu_lidar.isApprox(inverse(imu.T_lidar_cam), 1e-12));

  // The noise-free map's points, projected by OpenCV through the file's distortion at the true pose, land
  // on pixels whose true depth is theirs (unless something nearer hides them). Projected as a pinhole
  // instead, far fewer do: the depth, and so the frames, were rendered through the lens.
  const cv::Matx33d Kcv(K.fx, 0, K.cx, 0, K.fy, K.cy, 0, 0, 1);
  for (const size_t f : {size_t{2}, size_t{7}}) {
    const io::Image depth = io::read_image(o.out / "gt/depth" / s.frames[f].image.filename());
    const Eigen::Isometry3d T_cam_world(inverse(matrix(s.gt->poses[f])));
    std::vector<cv::Point3d> points;
    std::vector<double> z;
    for (size_t i = 0; i < s.gt->map->size(); i += 7) {
      const Eigen::Vector3d p = T_cam_world * s.gt->map->positions[i];
      if (p.z() < 0.5 || std::hypot(p.x(), p.y()) > 1.2 * p.z()) continue;  // ahead, within the lens' range
      points.emplace_back(p.x(), p.y(), p.z());
      z.push_back(p.z());
    }
    ASSERT_GT(points.size(), 1000u);
    auto agreeing = [&](const std::vector<double>& distortion) {
      std::vector<cv::Point2d> px;
      cv::projectPoints(points, cv::Vec3d(0, 0, 0), cv::Vec3d(0, 0, 0), Kcv, distortion, px);
      size_t inside = 0, agree = 0;
      for (size_t i = 0; i < px.size(); ++i) {
        const long u = std::lround(px[i].x), v = std::lround(px[i].y);
        if (u < 0 || v < 0 || u >= K.width || v >= K.height) continue;
        ++inside;
        const double d_m = depth.data[static_cast<size_t>(v) * K.width + u] / 1000.0;
        agree += std::abs(d_m - z[i]) < 0.02 * z[i] + 0.01 ? 1 : 0;
      }
      return inside ? static_cast<double>(agree) / static_cast<double>(inside) : 0.0;
    };
    const double through_lens = agreeing(K.distortion), as_pinhole = agreeing({});
    EXPECT_GT(through_lens, 0.85) << "frame " << f;
    EXPECT_LT(as_pinhole, through_lens - 0.1) << "frame " << f << ": " << through_lens << " through the lens";
  }
}

TEST_F(SynthRigTest, ExportedAsABagAndImportedWithTheFileItIsTheSameScene) {
  if (!io::ros_bag_writer_available()) GTEST_FAIL() << "this build cannot write ROS bags (ci/setup)";
  const SynthOptions o = rigged();  // import bag checks the frames against the file's 640 x 512
  generate_synthetic_scene(o);
  io::BagExportOptions e;
  e.scene = o.out;
  e.out = dir_ / "recording.bag";
  const io::BagExportReport exported = io::export_bag(e);
  EXPECT_EQ(exported.frames, 10u);
  EXPECT_EQ(exported.scans, 10u);
  EXPECT_EQ(exported.odometry, 10u);
  EXPECT_GT(exported.imu, 100u);
  io::TumExportOptions t;
  t.scene = o.out;
  t.out = dir_ / "truth_imu.txt";
  t.ground_truth = true;
  t.imu = true;
  ASSERT_EQ(io::export_tum(t), 10u);

  io::BagImportOptions i;
  i.bag = e.out;
  i.calib = kCalib;
  i.topics.odom = "/odom";
  i.ground_truth = t.out;
  i.out = dir_ / "imported";
  const io::BagImportReport imported = io::import_bag(i);
  EXPECT_EQ(imported.frames, 10u);
  bool said_block = false;
  for (const auto& note : imported.notes) said_block |= note.find("'Handsfree IMU'") != std::string::npos;
  EXPECT_TRUE(said_block);

  const io::Scene a = io::read_scene(o.out), b = io::read_scene(i.out);
  EXPECT_EQ(b.config.poses_frame, io::PoseFrame::kImu);
  EXPECT_TRUE(b.config.T_cam_lidar.isApprox(a.config.T_cam_lidar, 1e-12));
  EXPECT_TRUE(b.config.T_imu_lidar.isApprox(a.config.T_imu_lidar, 1e-12));
  EXPECT_EQ(b.config.camera.distortion, a.config.camera.distortion);
  EXPECT_EQ(io::load_frame(i.out, b, 4).data, io::load_frame(o.out, a, 4).data);
  const io::PointCloud scan_a = io::read_pcd(o.out / a.scans[6].file),
                       scan_b = io::read_pcd(i.out / b.scans[6].file);
  ASSERT_EQ(scan_a.size(), scan_b.size());
  for (size_t k = 0; k < scan_a.size(); k += 50)
    EXPECT_LT((scan_a.positions[k] - scan_b.positions[k]).norm(), 1e-5);  // float32 in the message
  EXPECT_EQ(b.imu.size(), a.imu.size());

  // The IMU odometry, brought back to the camera through the file's extrinsics, is the synthetic estimate;
  // the IMU truth likewise is the camera truth. The lever arm between them is the file's 1.03 m.
  const auto camera_b = io::camera_poses_at_frames(b);
  ASSERT_EQ(camera_b.size(), a.poses.size());
  const Eigen::Matrix4d T_cam_imu = a.config.T_cam_lidar * inverse(a.config.T_imu_lidar);
  const double lever_arm_m = T_cam_imu.block<3, 1>(0, 3).norm();
  EXPECT_NEAR(lever_arm_m, 1.03, 0.01);
  for (size_t k = 0; k < a.poses.size(); ++k) {
    ASSERT_TRUE(camera_b[k]);
    const Eigen::Matrix4d expected = matrix(a.poses[k]);
    EXPECT_LT((*camera_b[k] - expected).norm(), 1e-9) << "frame " << k;
    EXPECT_LT((matrix(b.gt->poses[k]) - matrix(a.gt->poses[k]) * T_cam_imu).norm(), 1e-9) << "frame " << k;
    EXPECT_NEAR((b.gt->poses[k].p_world - a.gt->poses[k].p_world).norm(), lever_arm_m, 1e-9);
  }
}

}  // namespace
}  // namespace litgs::host::synth
