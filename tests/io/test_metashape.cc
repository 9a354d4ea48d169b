#include <gtest/gtest.h>

#include <Eigen/Geometry>
#include <algorithm>
#include <iostream>

#include "io/control_points.h"
#include "io/metashape.h"
#include "tests/io/io_test.h"

namespace litgs::io {
namespace {

class MetashapeTest : public testing::TempDirTest {};

std::filesystem::path dunr() {
  return testing::data_dir() / "thermitage-dunr/metashape";
}

TEST_F(MetashapeTest, ReadsTheDunrDocument) {
  const MetashapeDocument d = read_metashape_xml(dunr() / "DUNR-ImgCoords-TIR.xml");
  ASSERT_EQ(d.cameras.size(), 45u);
  ASSERT_EQ(d.sensors.size(), 2u);
  const MetashapeSensor* s = d.sensor(0);
  ASSERT_NE(s, nullptr);
  EXPECT_EQ(s->width, 640);
  EXPECT_EQ(s->height, 512);
  ASSERT_TRUE(s->calibration.has_value());
  EXPECT_DOUBLE_EQ(s->calibration->f, 773.73270872853072);
  EXPECT_EQ(s->calibration->cx, 0.0);  // not in this file
  EXPECT_EQ(d.cameras[0].label, "22-18-41-880-radiometric");
  ASSERT_TRUE(d.cameras[0].T_chunk_cam.has_value());
  EXPECT_DOUBLE_EQ((*d.cameras[0].T_chunk_cam)(0, 3), 5.1591234358379605);
  EXPECT_DOUBLE_EQ(d.chunk.scale, 0.74882383728349777);
  EXPECT_DOUBLE_EQ(d.chunk.t.x(), 999.59453537619925);
  EXPECT_DOUBLE_EQ(d.chunk.R(2, 1), -0.99460274173083396);
  ASSERT_EQ(d.markers.size(), 6u);
  EXPECT_EQ(d.markers[0].label, "P1");
  EXPECT_EQ(d.markers[0].observations.size(), 7u);
  EXPECT_EQ(d.markers[2].observations.size(), 11u);
  EXPECT_FALSE(d.markers[1].reference_enabled);
  // Every camera sits a few metres in front of the facade (Northing ~1009.5), looking at it (+y world).
  for (const auto& c : d.cameras) {
    const Eigen::Matrix4d T = d.T_world_cam(c);
    EXPECT_GT(T(1, 3), 995.0) << c.label;
    EXPECT_LT(T(1, 3), 1008.0) << c.label;
    EXPECT_GT(T(1, 2), 0.8) << c.label;  // optical axis (camera z) points along world +y
  }
}

TEST_F(MetashapeTest, ReadsControlPointsCsv) {
  const auto points = read_control_points_csv(dunr() / "DUNR-GeomControl.csv");
  ASSERT_EQ(points.size(), 12u);  // BS1 and P1..P11
  EXPECT_EQ(points[0].id, "BS1");
  EXPECT_EQ(points[1].id, "P1");
  EXPECT_EQ(points[1].p_world, Eigen::Vector3d(997.1110, 1009.6704, 104.1154));
  EXPECT_EQ(points[11].id, "P11");
  EXPECT_DOUBLE_EQ(points[11].accuracy_m, 0.003);
}

// The control points through the stored poses with a plain pinhole model: about 3 px
// (tests/data/thermitage-dunr/PROVENANCE.md).
TEST_F(MetashapeTest, ControlPointsReprojectWithinAFewPixels) {
  const MetashapeDocument d = read_metashape_xml(dunr() / "DUNR-ImgCoords-TIR.xml");
  const auto points = read_control_points_csv(dunr() / "DUNR-GeomControl.csv");
  std::vector<double> errors;
  for (const auto& m : d.markers) {
    const auto it =
        std::find_if(points.begin(), points.end(), [&](const ControlPoint& p) { return p.id == m.label; });
    ASSERT_NE(it, points.end()) << m.label;
    EXPECT_LT((it->p_world - *m.reference).norm(), 1e-6) << "the XML reference differs from the survey";
    for (const auto& o : m.observations) {
      const MetashapeCamera* c = d.camera(o.camera_id);
      const MetashapeCalibration& cal = *d.sensor(c->sensor_id)->calibration;
      const Eigen::Matrix4d T_cam_world = d.T_world_cam(*c).inverse();
      const Eigen::Vector3d p_cam =
          T_cam_world.topLeftCorner<3, 3>() * it->p_world + T_cam_world.topRightCorner<3, 1>();
      ASSERT_GT(p_cam.z(), 0) << m.label << " behind camera " << c->label;
      errors.push_back((cal.project(p_cam) - o.uv).norm());
    }
  }
  ASSERT_EQ(errors.size(), 7u + 9 + 11 + 12 + 12 + 9);
  std::sort(errors.begin(), errors.end());
  const double median = errors[errors.size() / 2];
  std::cout << "control point reprojection: median " << median << " px, max " << errors.back() << " px over "
            << errors.size() << " observations\n";
  // Measured: median 3.19 px, max 4.86 px over the 60 observations of P1..P6.
  EXPECT_GT(median, 2.5);  // the poses are good, not perfect
  EXPECT_LT(median, 4.0);
  EXPECT_LT(errors.back(), 6.0);
}

TEST_F(MetashapeTest, ReadsTheStandAloneCalibration) {
  const MetashapeCalibration c = read_metashape_calibration(dunr() / "DUNR-GeoCamCal-TIR.xml");
  EXPECT_EQ(c.width, 640);
  EXPECT_EQ(c.height, 512);
  EXPECT_DOUBLE_EQ(c.f, 767.12843123113532);
  EXPECT_DOUBLE_EQ(c.cx, -7.4152602539158226);
  EXPECT_DOUBLE_EQ(c.p2, 9.3220444877214486e-05);
}

TEST_F(MetashapeTest, BadDocumentsNameTheLine) {
  testing::expect_io_error(
      [&] { read_metashape_xml(write_text("a.xml", "<document><chunk>\n<cameras>\n</chunk>")); },
      {"a.xml:", "malformed XML"});
  const std::string head =
      "<document><chunk>\n<sensors><sensor id=\"0\"><resolution width=\"4\" "
      "height=\"4\"/></sensor></sensors>\n"
      "<cameras>\n";
  testing::expect_io_error(
      [&] {
        read_metashape_xml(
            write_text("b.xml", head + "<camera id=\"0\" sensor_id=\"0\" label=\"c\">\n<transform>1 0 0 0 0 "
                                       "1 0 0 0 0 1 0 0 0 0</transform>"
                                       "</camera></cameras></chunk></document>"));
      },
      {"b.xml:5:", "holds 15 numbers, expected 16"});
  testing::expect_io_error(
      [&] {
        read_metashape_xml(write_text(
            "c.xml", head + "<camera id=\"0\" sensor_id=\"3\" label=\"c\"/></cameras></chunk></document>"));
      },
      {"c.xml:4:", "unknown sensor 3"});
  testing::expect_io_error(
      [&] {
        read_metashape_xml(
            write_text("d.xml", head + "<camera id=\"0\" sensor_id=\"0\" label=\"c\">\n<transform>2 0 0 0 0 "
                                       "1 0 0 0 0 1 0 0 0 0 1</transform>"
                                       "</camera></cameras></chunk></document>"));
      },
      {"d.xml:5:", "not rigid"});
  testing::expect_io_error([&] { read_control_points_csv(write_text("p.csv", "id,x,y,z,a\nP1,1,2,3\n")); },
                           {"p.csv:2:", "expected 5"});
  testing::expect_io_error(
      [&] { read_control_points_csv(write_text("q.csv", "id,x,y,z,a\nP1,1,nan,3,0\n")); },
      {"q.csv:2:", "non-finite"});
}

}  // namespace
}  // namespace litgs::io
