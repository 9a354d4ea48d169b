#include <gtest/gtest.h>

#include <Eigen/Geometry>
#include <Eigen/LU>
#include <algorithm>
#include <cstdio>
#include <map>
#include <regex>
#include <sstream>

#include "io/control_points.h"
#include "io/file_bytes.h"
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

// The control points' reprojection errors straight from the XML's text, written apart from io/metashape.cc
// and the importer: its own parsing (string search and regular expressions on the file), the chunk's
// similarity X_world = s R X_chunk + t inverted by hand, each camera's <transform> (T_chunk_cam, row-major)
// inverted as a rigid motion in chunk units, and Metashape's frame model in its own pixel coordinates
// (origin at the top-left corner of the image): u = w/2 + cx + f x/z, v = h/2 + cy + f y/z. Keyed by
// (marker id, camera id); the marker positions are the XML's <reference> elements.
std::map<std::pair<int, int>, double> xml_reprojection_errors(const std::filesystem::path& xml) {
  const std::string text = read_file_bytes(xml);
  const auto numbers = [](const std::string& s) {
    std::istringstream in(s);
    std::vector<double> v;
    for (double x; in >> x;) v.push_back(x);
    return v;
  };
  // The text of the first element <tag ...>text</tag> at or after `from`.
  const auto element = [&](size_t from, const std::string& tag) {
    const size_t open = text.find("<" + tag, from);
    if (open == std::string::npos) throw std::runtime_error("no <" + tag + ">");
    const size_t a = text.find('>', open) + 1;
    return text.substr(a, text.find("</" + tag + ">", a) - a);
  };
  // Sensor 0 (every camera's): its calibration's resolution and f. This file gives no cx, cy or distortion.
  const size_t sensor = text.find("<sensor id=\"0\"");
  const std::string calibration = element(sensor, "calibration");
  if (calibration.find("<cx>") != std::string::npos || calibration.find("<k1>") != std::string::npos)
    throw std::runtime_error("the test's pinhole assumes a calibration with f only");
  std::smatch m;
  if (!std::regex_search(calibration, m, std::regex(R"re(width="(\d+)" height="(\d+)")re")))
    throw std::runtime_error("no resolution");
  const double w = std::stod(m[1]), h = std::stod(m[2]);
  const double f = numbers(element(text.find("<calibration", sensor), "f")).at(0);
  // The chunk's transform: the <transform> after </markers>.
  const size_t chunk = text.find("<transform>", text.find("</markers>"));
  const std::vector<double> r = numbers(element(chunk, "rotation"));
  const std::vector<double> t = numbers(element(chunk, "translation"));
  const double scale = numbers(element(chunk, "scale")).at(0);
  Eigen::Matrix3d R;
  R << r.at(0), r.at(1), r.at(2), r.at(3), r.at(4), r.at(5), r.at(6), r.at(7), r.at(8);
  const Eigen::Vector3d tw(t.at(0), t.at(1), t.at(2));
  // Cameras.
  std::map<int, Eigen::Matrix4d> T_chunk_cam;
  const std::regex camera(R"re(<camera id="(\d+)"[^>]*>\s*<transform>([^<]+)</transform>)re");
  for (auto it = std::sregex_iterator(text.begin(), text.end(), camera); it != std::sregex_iterator(); ++it) {
    const std::vector<double> v = numbers((*it)[2]);
    Eigen::Matrix4d T;
    for (int i = 0; i < 16; ++i) T(i / 4, i % 4) = v.at(static_cast<size_t>(i));
    T_chunk_cam[std::stoi((*it)[1])] = T;
  }
  // Markers: world references, then the observations in <frames>.
  std::map<int, Eigen::Vector3d> world;
  const std::regex reference(
      R"re(<marker id="(\d+)" label="[^"]*">\s*<reference x="([^"]+)" y="([^"]+)" z="([^"]+)")re");
  for (auto it = std::sregex_iterator(text.begin(), text.end(), reference); it != std::sregex_iterator();
       ++it)
    world[std::stoi((*it)[1])] = {std::stod((*it)[2]), std::stod((*it)[3]), std::stod((*it)[4])};
  std::map<std::pair<int, int>, double> errors;
  const std::regex location(R"re(<location camera_id="(\d+)"[^>]* x="([^"]+)" y="([^"]+)")re");
  for (size_t at = text.find("<marker marker_id=\"", text.find("<frames")); at != std::string::npos;
       at = text.find("<marker marker_id=\"", at + 1)) {
    const int id = std::stoi(text.substr(at + 19));
    const std::string block = text.substr(at, text.find("</marker>", at) - at);
    for (auto it = std::sregex_iterator(block.begin(), block.end(), location); it != std::sregex_iterator();
         ++it) {
      const int cam = std::stoi((*it)[1]);
      const Eigen::Vector3d x_chunk = R.transpose() * (world.at(id) - tw) / scale;
      const Eigen::Matrix4d& T = T_chunk_cam.at(cam);
      const Eigen::Vector3d x = T.topLeftCorner<3, 3>().transpose() * (x_chunk - T.topRightCorner<3, 1>());
      const Eigen::Vector2d uv(w / 2 + f * x.x() / x.z(), h / 2 + f * x.y() / x.z());
      errors[{id, cam}] = (uv - Eigen::Vector2d(std::stod((*it)[2]), std::stod((*it)[3]))).norm();
    }
  }
  return errors;
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

  // The imported scene alone (pinhole fx fy cx cy, recentred TUM poses, the surveyed CSV) reprojects the
  // control points exactly as the XML does when read by the independent path above (xml_reprojection_errors:
  // every observation's error the same to 1e-6 px, so the importer's frame, offset and pixel-convention
  // conversions are exact; about 3.19 px median, Metashape's own residual on these hand-placed markers).
  const auto points = read_control_points_csv(data / "metashape/DUNR-GeomControl.csv");
  const std::map<std::pair<int, int>, double> want = xml_reprojection_errors(o.xml);
  std::vector<double> errors, want_sorted;
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
      const auto w = want.find({m.id, obs.camera_id});
      ASSERT_NE(w, want.end()) << m.label << " in camera " << obs.camera_id;
      EXPECT_NEAR(errors.back(), w->second, 1e-6) << m.label << " in camera " << obs.camera_id;
    }
  }
  ASSERT_EQ(errors.size(), want.size());
  ASSERT_GT(errors.size(), 40u);  // 60 observations of 6 markers in this file
  for (const auto& [key, e] : want) want_sorted.push_back(e);
  std::sort(errors.begin(), errors.end());
  std::sort(want_sorted.begin(), want_sorted.end());
  EXPECT_NEAR(errors[errors.size() / 2], want_sorted[want_sorted.size() / 2], 1e-6);
  std::printf("control point reprojection: median %.4f px over %zu observations\n", errors[errors.size() / 2],
              errors.size());
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
