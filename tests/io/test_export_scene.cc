#include <gtest/gtest.h>

#include <Eigen/Geometry>
#include <algorithm>

#include "io/colmap.h"
#include "io/export_scene.h"
#include "io/scene.h"
#include "io/tum.h"
#include "tests/io/io_test.h"

namespace litgs::io {
namespace {

class ExportSceneTest : public testing::TempDirTest {
 protected:
  // An IMU-posed scene with a map, anchors, ground truth, a time offset and a world offset.
  Scene make_scene() const {
    Scene s;
    SceneConfig& c = s.config;
    c.camera.width = 4;
    c.camera.height = 3;
    c.camera.fx = c.camera.fy = 10;
    c.camera.cx = 1.5;
    c.camera.cy = 1;
    c.camera.bit_depth = 8;
    c.T_cam_lidar << 0, -1, 0, 0.1, 0, 0, -1, 0.2, 1, 0, 0, 0.3, 0, 0, 0, 1;
    c.T_imu_lidar.topRightCorner<3, 1>() = Eigen::Vector3d(-0.5, 0, 0.25);
    c.time_offset_cam_lidar_s = 0.05;
    c.poses_frame = PoseFrame::kImu;
    c.world_offset_m = {1000, 2000, 100};
    for (double t : {0.95, 1.45, 5.0}) s.frames.push_back({t, frame_file_name(t)});  // 5.0: no pose
    for (int i = 0; i < 3; ++i) {
      TumPose p;
      p.t_s = 1.0 + 0.5 * i;
      p.p_world = {1.0 * i, 0, 0};
      p.q_world_body = Eigen::Quaterniond(Eigen::AngleAxisd(0.2 * i, Eigen::Vector3d::UnitZ()));
      s.poses.push_back(p);
    }
    PointCloud map;
    for (int i = 0; i < 10; ++i) map.positions.push_back({1.0 * i, 2, 3});
    s.map = map;
    GroundTruth gt;
    gt.poses = s.poses;
    gt.poses[1].has_rotation = false;
    s.gt = gt;
    return s;
  }
  void write(const Scene& s, const std::filesystem::path& dir) const {
    write_scene(dir, s, [&](size_t i) {
      Image im;
      im.width = 4;
      im.height = 3;
      im.data.assign(12, static_cast<uint16_t>(10 * i));
      return im;
    });
  }
};

TEST_F(ExportSceneTest, ColmapFromImuPosesWithTimeOffsetAndMapPoints) {
  const Scene s = make_scene();
  write(s, dir_ / "scene");
  ColmapExportOptions o;
  o.scene = dir_ / "scene";
  o.out = dir_ / "colmap";
  o.max_points = 4;  // 10 map points -> every 3rd: 0, 3, 6, 9
  const ColmapExportReport r = export_colmap(o);
  EXPECT_EQ(r.images, 2u);
  EXPECT_EQ(r.skipped_without_pose, 1u);
  EXPECT_EQ(r.points, 4u);
  const auto said = [&](const std::string& text) {
    return std::any_of(r.notes.begin(), r.notes.end(),
                       [&](const std::string& n) { return n.find(text) != std::string::npos; });
  };
  EXPECT_TRUE(said("points3D from the LiDAR map (10 points)"));
  EXPECT_TRUE(said("kept one point in 3"));
  const ColmapModel m = read_colmap_model(o.out / "sparse/0");
  EXPECT_EQ(m.cameras.at(1).model, ColmapCameraModel::kPinhole);
  EXPECT_EQ(m.cameras.at(1).params, (std::vector<double>{10, 10, 2, 1.5}));
  ASSERT_EQ(m.points.size(), 4u);
  EXPECT_EQ(m.points[1].xyz, Eigen::Vector3d(1003, 2002, 103));  // original coordinates
  EXPECT_EQ(m.points[1].error_px, -1);
  ASSERT_EQ(m.images.size(), 2u);
  EXPECT_EQ(m.images[0].name, "0.95.png");
  EXPECT_TRUE(std::filesystem::exists(o.out / "images/1.45.png"));
  // Frame 0.95 + offset 0.05 = IMU pose 0 exactly; frame 1.45 -> 1.5 = IMU pose 1. The camera centre is the
  // IMU pose applied to the camera's position in the IMU frame: T_imu_lidar * (camera centre in LiDAR).
  const Eigen::Matrix3d R_cl = s.config.T_cam_lidar.topLeftCorner<3, 3>();
  const Eigen::Vector3d c_lidar = -R_cl.transpose() * s.config.T_cam_lidar.topRightCorner<3, 1>();
  const Eigen::Vector3d c_imu = c_lidar + Eigen::Vector3d(-0.5, 0, 0.25);
  for (int i = 0; i < 2; ++i) {
    const Eigen::Vector3d expected = s.poses[static_cast<size_t>(i)].q_world_body * c_imu +
                                     s.poses[static_cast<size_t>(i)].p_world + s.config.world_offset_m;
    EXPECT_LT((m.images[static_cast<size_t>(i)].T_world_cam().topRightCorner<3, 1>() - expected).norm(),
              1e-9);
  }
}

TEST_F(ExportSceneTest, ColmapWithoutAnyPointSourceSaysSo) {
  Scene s = make_scene();
  s.map.reset();
  s.config.has_lidar_map = false;
  s.anchors.clear();
  write(s, dir_ / "scene");
  ColmapExportOptions o;
  o.scene = dir_ / "scene";
  o.out = dir_ / "colmap";
  const ColmapExportReport r = export_colmap(o);
  EXPECT_EQ(r.points, 0u);
  EXPECT_TRUE(std::any_of(r.notes.begin(), r.notes.end(), [](const std::string& n) {
    return n.find("no points3D: the scene has no sfm/") != std::string::npos;
  }));
}

TEST_F(ExportSceneTest, TumStoredCameraAndGroundTruth) {
  const Scene s = make_scene();
  write(s, dir_ / "scene");
  TumExportOptions o;
  o.scene = dir_ / "scene";
  o.out = dir_ / "a.tum";
  EXPECT_EQ(export_tum(o), 3u);
  auto poses = read_tum(o.out);
  EXPECT_EQ(poses[2].p_world, Eigen::Vector3d(1002, 2000, 100));
  o.recentred = true;
  export_tum(o);
  EXPECT_EQ(read_tum(o.out)[2].p_world, Eigen::Vector3d(2, 0, 0));
  o.ground_truth = true;
  EXPECT_EQ(export_tum(o), 3u);
  EXPECT_FALSE(read_tum(o.out)[1].has_rotation);  // stays 0 0 0 0
  o.ground_truth = false;
  o.camera = true;
  EXPECT_EQ(export_tum(o), 2u);  // frame 5.0 has no pose
  poses = read_tum(o.out);
  EXPECT_EQ(poses[0].t_s, 0.95);  // camera timestamps
  o.ground_truth = true;
  EXPECT_THROW(export_tum(o), std::invalid_argument);
}

}  // namespace
}  // namespace litgs::io
