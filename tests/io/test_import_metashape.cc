#include <gtest/gtest.h>

#include <Eigen/Geometry>
#include <Eigen/LU>
#include <algorithm>

#include "io/control_points.h"
#include "io/image.h"
#include "io/import_metashape.h"
#include "io/metashape.h"
#include "io/scene.h"
#include "tests/io/io_test.h"

namespace litgs::io {
namespace {

class ImportMetashapeTest : public testing::TempDirTest {};

// "22-18-41-880-radiometric" -> 80321.88, computed as the importer documents it.
double label_seconds(const std::string& label) {
  return std::stoi(label.substr(0, 2)) * 3600.0 + std::stoi(label.substr(3, 2)) * 60.0 +
         std::stoi(label.substr(6, 2)) + std::stoi(label.substr(9, 3)) / 1000.0;
}

// The 8-bit frames (tests/data has all 45 of them; of the 16-bit TIFFs only 3, too few for an import).
TEST_F(ImportMetashapeTest, ImportsDunrAndReadsItBack) {
  const auto data = testing::data_dir() / "thermitage-dunr";
  MetashapeImportOptions o;
  o.xml = data / "metashape/DUNR-ImgCoords-TIR.xml";
  o.images = data / "radjpg";
  o.out = dir_ / "scene";
  const MetashapeImportReport report = import_metashape(o);
  EXPECT_EQ(report.frames, 45u);
  EXPECT_EQ(report.skipped_unaligned, 0u);
  EXPECT_TRUE(report.notes.empty());

  const Scene scene = read_scene(o.out);
  const SceneConfig& c = scene.config;
  EXPECT_FALSE(c.has_lidar_map);
  EXPECT_EQ(c.poses_frame, PoseFrame::kCamera);
  EXPECT_EQ(c.camera.width, 640);
  EXPECT_EQ(c.camera.bit_depth, 8);
  EXPECT_DOUBLE_EQ(c.camera.fx, 773.73270872853072);
  EXPECT_DOUBLE_EQ(c.camera.cx, 319.5);  // no offset in this file: the centre, in pixel-centre coordinates
  EXPECT_TRUE(c.camera.distortion.empty());
  EXPECT_EQ(c.world_offset_m, report.world_offset_m);
  EXPECT_NEAR(c.world_offset_m.y(), 1005, 5);  // the cameras stand a few metres before the facade
  ASSERT_EQ(scene.frames.size(), 45u);
  ASSERT_EQ(scene.poses.size(), 45u);
  EXPECT_DOUBLE_EQ(scene.frames[0].t_s, 22 * 3600 + 18 * 60 + 41.880);  // 22-18-41-880-radiometric
  EXPECT_EQ(scene.frames[0].t_s, scene.poses[0].t_s);
  for (const auto& p : scene.poses) EXPECT_LT(p.p_world.norm(), 20.0) << "recentred";

  // The decoded pixel values arrive unchanged (the JPEG is decoded once and stored losslessly).
  EXPECT_EQ(load_frame(o.out, scene, 0).data, read_image(data / "radjpg/22-18-41-880-radiometric.jpg").data);

  // Poses: scene pose + offset equals the XML's camera-to-world, for every camera.
  const MetashapeDocument doc = read_metashape_xml(o.xml);
  for (const auto& cam : doc.cameras) {
    const Eigen::Matrix4d T = doc.T_world_cam(cam);
    const double t = label_seconds(cam.label);
    const auto it = std::find_if(scene.frames.begin(), scene.frames.end(),
                                 [&](const SceneFrame& f) { return f.t_s == t; });
    ASSERT_NE(it, scene.frames.end()) << cam.label;
    const TumPose& p = scene.poses[static_cast<size_t>(it - scene.frames.begin())];
    EXPECT_LT((p.p_world + c.world_offset_m - T.topRightCorner<3, 1>()).norm(), 1e-9) << cam.label;
    EXPECT_LT((p.q_world_body.toRotationMatrix() - T.topLeftCorner<3, 3>()).norm(), 1e-12) << cam.label;
  }

  // The imported scene alone (pinhole fx fy cx cy, recentred TUM poses) reprojects the control points as the
  // XML does: the same 3.19 px median (marker pixels moved to the pixel-centre convention).
  const auto points = read_control_points_csv(data / "metashape/DUNR-GeomControl.csv");
  std::vector<double> errors;
  for (const auto& m : doc.markers) {
    const auto cp =
        std::find_if(points.begin(), points.end(), [&](const ControlPoint& p) { return p.id == m.label; });
    ASSERT_NE(cp, points.end());
    for (const auto& obs : m.observations) {
      const MetashapeCamera* cam = doc.camera(obs.camera_id);
      const Eigen::Matrix4d T = doc.T_world_cam(*cam);
      const auto f = std::find_if(scene.poses.begin(), scene.poses.end(), [&](const TumPose& p) {
        return (p.p_world + c.world_offset_m - T.topRightCorner<3, 1>()).norm() < 1e-9;
      });
      ASSERT_NE(f, scene.poses.end());
      const Eigen::Vector3d x = f->q_world_body.conjugate() * (cp->p_world - c.world_offset_m - f->p_world);
      const Eigen::Vector2d uv(c.camera.fx * x.x() / x.z() + c.camera.cx,
                               c.camera.fy * x.y() / x.z() + c.camera.cy);
      errors.push_back((uv - (obs.uv - Eigen::Vector2d(0.5, 0.5))).norm());
    }
  }
  std::sort(errors.begin(), errors.end());
  EXPECT_NEAR(errors[errors.size() / 2], 3.186, 0.01);
}

TEST_F(ImportMetashapeTest, StandAloneCalibrationReplacesTheSensorsOwn) {
  const auto data = testing::data_dir() / "thermitage-dunr";
  MetashapeImportOptions o;
  o.xml = data / "metashape/DUNR-ImgCoords-TIR.xml";
  o.images = data / "radjpg";
  o.out = dir_ / "scene";
  o.calibration = data / "metashape/DUNR-GeoCamCal-TIR.xml";
  o.world_offset_m = Eigen::Vector3d(1000, 1000, 100);
  import_metashape(o);
  const SceneConfig c = read_scene(o.out, {.check_images = false}).config;
  EXPECT_DOUBLE_EQ(c.camera.fx, 767.12843123113532);
  EXPECT_DOUBLE_EQ(c.camera.cx, 320 - 7.4152602539158226 - 0.5);
  ASSERT_EQ(c.camera.distortion.size(), 4u);
  EXPECT_DOUBLE_EQ(c.camera.distortion[2], 9.3220444877214486e-05);  // OpenCV p1 = Metashape p2
  EXPECT_DOUBLE_EQ(c.camera.distortion[3], -0.00063888289217806245);
  EXPECT_EQ(c.world_offset_m, Eigen::Vector3d(1000, 1000, 100));
}

TEST_F(ImportMetashapeTest, MissingImagesAreNamed) {
  const auto data = testing::data_dir() / "thermitage-dunr";
  MetashapeImportOptions o;
  o.xml = data / "metashape/DUNR-ImgCoords-TIR.xml";
  o.images = dir_;  // empty
  o.out = dir_ / "scene";
  testing::expect_io_error([&] { import_metashape(o); }, {"22-18-41-880-radiometric", "no image for camera"});
  EXPECT_FALSE(std::filesystem::exists(dir_ / "scene/scene.yaml"));
}

}  // namespace
}  // namespace litgs::io
