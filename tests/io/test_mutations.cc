// Corrupted inputs: every parser, given truncations and random byte changes of a valid file, must either
// read something or throw IoError; never crash, hang, or leak another exception type. (A deterministic
// stand-in until the libFuzzer targets of issue 5 exist; run it under ASan/UBSan for full value.)
#include <gtest/gtest.h>

#include <algorithm>
#include <cstdlib>
#include <functional>
#include <random>

#include "io/colmap.h"
#include "io/file_bytes.h"
#include "io/image.h"
#include "io/m2dgr_calib.h"
#include "io/metashape.h"
#include "io/pcd.h"
#include "io/ply_points.h"
#include "io/scene_text.h"
#include "io/scene_yaml.h"
#include "io/tum.h"
#include "tests/io/io_test.h"

namespace litgs::io {
namespace {

class MutationTest : public testing::TempDirTest {
 protected:
  // Runs `parse` on `count` mutants of `original` (written as `name`): truncations, byte flips, and
  // insertions of characters that parsers treat specially.
  void run(const std::string& name, const std::string& original,
           const std::function<void(const std::filesystem::path&)>& parse, int count = 300) {
    // LITGS_MUTATION_SCALE=N runs N times as many mutants (for sanitizer runs).
    if (const char* scale = std::getenv("LITGS_MUTATION_SCALE")) count *= std::max(1, std::atoi(scale));
    std::mt19937 rng(12345);
    const std::string specials = "\n\r\t ,[]:#-+.eEnN0\xff\x00";
    int failures = 0;
    for (int i = 0; i < count; ++i) {
      std::string m = original;
      const int kind = i % 3;
      if (kind == 0) {
        m.resize(rng() % (m.size() + 1));
      } else {
        const int edits = 1 + static_cast<int>(rng() % 4);
        for (int e = 0; e < edits && !m.empty(); ++e) {
          const size_t at = rng() % m.size();
          if (kind == 1)
            m[at] = static_cast<char>(rng() & 0xff);
          else
            m.insert(m.begin() + static_cast<std::ptrdiff_t>(at), specials[rng() % specials.size()]);
        }
      }
      const auto path = write_text(name, m);
      try {
        parse(path);
      } catch (const IoError&) {
        // expected for most mutants
      } catch (const std::exception& e) {
        if (++failures <= 5)
          ADD_FAILURE() << name << " mutant " << i << ": non-IoError exception: " << e.what();
      }
    }
  }
};

TEST_F(MutationTest, TextFormats) {
  run("poses.txt", "# t x y z qx qy qz qw\n0.1 1 2 3 0 0 0 1\n0.2 1 2 3 0 0 0 0\n0.3 -1e-3 2 3 0.6 0 0 0.8\n",
      [](const auto& p) { read_tum(p); });
  run("anchors.txt", "1 2 3 1 0 0 1 0 1\n4 5 6 2 0.1 0 2 0 2\n", [](const auto& p) { read_anchors(p); });
  run("imu.csv", "t,gyro_x,gyro_y,gyro_z,accel_x,accel_y,accel_z\n1,0,0,0,0,0,9.8\n2,0.1,0,0,0,0,9.8\n",
      [](const auto& p) { read_imu_csv(p); });
  run("planes.txt", "0 0 1 -2\n0.6 0.8 0 1\n", [](const auto& p) { read_planes(p); });
  run(
      "calib.txt", read_file_bytes(testing::data_dir() / "m2dgr/calibration_results.txt"),
      [](const auto& p) { read_m2dgr_camera(p); }, 150);
}

TEST_F(MutationTest, SceneYaml) {
  SceneConfig c;
  c.camera.width = 640;
  c.camera.height = 512;
  c.camera.fx = c.camera.fy = 435.8;
  c.camera.cx = 320;
  c.camera.cy = 256;
  c.camera.distortion = {0.1, 0.01, 0, 0};
  write_scene_yaml(dir_ / "good.yaml", c);
  run("scene.yaml", read_file_bytes(dir_ / "good.yaml"), [](const auto& p) { read_scene_yaml(p); });
}

TEST_F(MutationTest, PointClouds) {
  PointCloud cloud;
  for (int i = 0; i < 20; ++i) cloud.positions.push_back({i * 0.5, -i * 0.25, 3.0});
  cloud.intensity.assign(20, 7.f);
  write_pcd(dir_ / "good.pcd", cloud);
  run("b.pcd", read_file_bytes(dir_ / "good.pcd"), [](const auto& p) { read_pcd(p); });
  run("a.pcd",
      "FIELDS x y z intensity\nSIZE 4 4 4 4\nTYPE F F F F\nCOUNT 1 1 1 1\nWIDTH 2\nHEIGHT 1\nPOINTS 2\n"
      "DATA ascii\n1 2 3 4\n5 6 7 8\n",
      [](const auto& p) { read_pcd(p); });
  const std::string ply = read_file_bytes(testing::data_dir() / "small-gicp-pair/source.ply");
  run("b.ply", ply.substr(0, 600), [](const auto& p) { read_ply_points(p); });
  const std::string ascii =
      read_file_bytes(testing::data_dir() / "thermitage-dunr/colmap-triangulated-points.ply");
  run("a.ply", ascii.substr(0, 900), [](const auto& p) { read_ply_points(p); });
}

TEST_F(MutationTest, ImagesAndXml) {
  Image im;
  im.width = 8;
  im.height = 6;
  im.bit_depth = 16;
  for (int i = 0; i < 48; ++i) im.data.push_back(static_cast<uint16_t>(i * 1000));
  write_image(dir_ / "good.png", im);
  write_image(dir_ / "good.tiff", im);
  run("m.png", read_file_bytes(dir_ / "good.png"), [](const auto& p) { read_image(p); });
  run("m.tiff", read_file_bytes(dir_ / "good.tiff"), [](const auto& p) { read_image(p); });
  const std::string xml =
      read_file_bytes(testing::data_dir() / "thermitage-dunr/metashape/DUNR-ImgCoords-TIR.xml");
  run(
      "m.xml", xml, [](const auto& p) { read_metashape_xml(p); }, 150);
}

TEST_F(MutationTest, ColmapModels) {
  // A consistent model: one mutated file at a time, the other two intact beside it.
  ColmapModel m;
  m.cameras[1] = {1, ColmapCameraModel::kOpenCv, 8, 6, {500, 501, 4, 3, 0.1, -0.01, 1e-3, 0}};
  ColmapImage a;
  a.id = 1;
  a.camera_id = 1;
  a.name = "1.5.png";
  a.t_cam_world = {1, 2, 3};
  a.points2d = {{{1.5, 2.5}, 1}, {{3, 4}, -1}};
  ColmapImage b = a;
  b.id = 2;
  b.name = "2.png";
  b.q_cam_world = Eigen::Quaterniond(0.6, 0, 0.8, 0);
  m.images = {a, b};
  m.points = {{1, {0.5, 1, 2}, {1, 2, 3}, 0.25, {{1, 0}, {2, 0}}}};
  for (bool binary : {false, true}) {
    const auto dir = dir_ / (binary ? "bin" : "txt");
    write_colmap_model(dir, m, binary);
    for (const char* stem : {"cameras", "images", "points3D"}) {
      const std::string name = std::string(binary ? "bin/" : "txt/") + stem + (binary ? ".bin" : ".txt");
      const std::string good = read_file_bytes(dir_ / name);
      run(
          name, good, [&](const auto&) { read_colmap_model(dir); }, 200);
      write_text(name, good);
    }
  }
}

}  // namespace
}  // namespace litgs::io
