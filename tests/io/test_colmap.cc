#include <gtest/gtest.h>

#include <Eigen/Geometry>
#include <cstring>
#include <fstream>

#include "io/colmap.h"
#include "io/export_scene.h"
#include "io/image.h"
#include "io/import_colmap.h"
#include "io/import_metashape.h"
#include "io/scene.h"
#include "tests/io/io_test.h"

namespace litgs::io {
namespace {

class ColmapTest : public testing::TempDirTest {
 protected:
  // A hand-written text model: two cameras, two images (one without points), two points.
  std::filesystem::path write_text_model(const std::string& sub = "txt") {
    write_text(sub + "/cameras.txt",
               "# Camera list with one line of data per camera:\n"
               "1 PINHOLE 8 6 500.5 501.25 4.25 3.125\n"
               "\n"
               "2 SIMPLE_RADIAL 8 6 400 4 3 -0.125\n");
    // Image 1: 90 degrees about z (qw = qz = sqrt(1/2)), t = (1, 2, 3). Image 2: identity at t = (0, 0, -5).
    write_text(sub + "/images.txt",
               "# Image list with two lines of data per image:\n"
               "1 0.70710678118654757 0 0 0.70710678118654757 1 2 3 1 10.5.png\n"
               "1.5 2.5 1 3.25 4.75 -1\n"
               "2 1 0 0 0 0 0 -5 2 sub dir/11.png\n"
               "\n");
    write_text(sub + "/points3D.txt",
               "# 3D point list\n"
               "1 0.5 -1.5 2.25 255 128 0 0.75 1 0\n"
               "7 1 2 3 1 2 3 1.5\n");
    return dir_ / sub;
  }
};

TEST_F(ColmapTest, ReadsHandWrittenTextWithKnownValues) {
  const ColmapModel m = read_colmap_model(write_text_model());
  ASSERT_EQ(m.cameras.size(), 2u);
  const ColmapCamera& c1 = m.cameras.at(1);
  EXPECT_EQ(c1.model, ColmapCameraModel::kPinhole);
  EXPECT_EQ(c1.width, 8u);
  EXPECT_EQ(c1.height, 6u);
  EXPECT_EQ(c1.params, (std::vector<double>{500.5, 501.25, 4.25, 3.125}));
  EXPECT_EQ(m.cameras.at(2).model, ColmapCameraModel::kSimpleRadial);
  ASSERT_EQ(m.images.size(), 2u);
  const ColmapImage& a = m.images[0];
  EXPECT_EQ(a.name, "10.5.png");
  ASSERT_EQ(a.points2d.size(), 2u);
  EXPECT_EQ(a.points2d[0].point3d_id, 1);
  EXPECT_EQ(a.points2d[1].xy, Eigen::Vector2d(3.25, 4.75));
  EXPECT_EQ(a.points2d[1].point3d_id, -1);
  EXPECT_EQ(m.images[1].name, "sub dir/11.png");  // names may hold spaces
  EXPECT_TRUE(m.images[1].points2d.empty());
  // cam_from_world: R = Rz(90), t = (1 2 3) -> camera centre -R^T t = (-2, 1, -3), camera x axis -> world -y.
  const Eigen::Matrix4d T = a.T_world_cam();
  EXPECT_LT((T.topRightCorner<3, 1>() - Eigen::Vector3d(-2, 1, -3)).norm(), 1e-12);
  EXPECT_LT((T.topLeftCorner<3, 3>() * Eigen::Vector3d::UnitX() + Eigen::Vector3d::UnitY()).norm(), 1e-12);
  EXPECT_EQ(Eigen::Vector3d(m.images[1].T_world_cam().col(3).head(3)), Eigen::Vector3d(0, 0, 5));
  ASSERT_EQ(m.points.size(), 2u);
  EXPECT_EQ(m.points[0].xyz, Eigen::Vector3d(0.5, -1.5, 2.25));
  EXPECT_EQ(m.points[0].rgb, (std::array<uint8_t, 3>{255, 128, 0}));
  EXPECT_EQ(m.points[0].error_px, 0.75);
  ASSERT_EQ(m.points[0].track.size(), 1u);
  EXPECT_EQ(m.points[0].track[0].image_id, 1u);
  EXPECT_EQ(m.points[1].id, 7u);
  EXPECT_TRUE(m.points[1].track.empty());
}

void expect_same(const ColmapModel& a, const ColmapModel& b) {
  ASSERT_EQ(a.cameras.size(), b.cameras.size());
  for (const auto& [id, c] : a.cameras) {
    const ColmapCamera& d = b.cameras.at(id);
    EXPECT_EQ(c.model, d.model);
    EXPECT_EQ(c.width, d.width);
    EXPECT_EQ(c.height, d.height);
    EXPECT_EQ(c.params, d.params);
  }
  ASSERT_EQ(a.images.size(), b.images.size());
  for (size_t i = 0; i < a.images.size(); ++i) {
    const ColmapImage &x = a.images[i], &y = b.images[i];
    EXPECT_EQ(x.id, y.id);
    EXPECT_EQ(x.q_cam_world.coeffs(), y.q_cam_world.coeffs());
    EXPECT_EQ(x.t_cam_world, y.t_cam_world);
    EXPECT_EQ(x.camera_id, y.camera_id);
    EXPECT_EQ(x.name, y.name);
    ASSERT_EQ(x.points2d.size(), y.points2d.size());
    for (size_t k = 0; k < x.points2d.size(); ++k) {
      EXPECT_EQ(x.points2d[k].xy, y.points2d[k].xy);
      EXPECT_EQ(x.points2d[k].point3d_id, y.points2d[k].point3d_id);
    }
  }
  ASSERT_EQ(a.points.size(), b.points.size());
  for (size_t i = 0; i < a.points.size(); ++i) {
    EXPECT_EQ(a.points[i].id, b.points[i].id);
    EXPECT_EQ(a.points[i].xyz, b.points[i].xyz);
    EXPECT_EQ(a.points[i].rgb, b.points[i].rgb);
    EXPECT_EQ(a.points[i].error_px, b.points[i].error_px);
    ASSERT_EQ(a.points[i].track.size(), b.points[i].track.size());
  }
}

TEST_F(ColmapTest, RoundTripsTextBinaryText) {
  const ColmapModel text = read_colmap_model(write_text_model());
  write_colmap_model(dir_ / "bin", text, true);
  EXPECT_TRUE(std::filesystem::exists(dir_ / "bin/points3D.bin"));
  const ColmapModel bin = read_colmap_binary(dir_ / "bin");
  expect_same(text, bin);
  write_colmap_model(dir_ / "txt2", bin, false);
  expect_same(text, read_colmap_text(dir_ / "txt2"));
}

// Little-endian bytes, written here independently of io/colmap.cc, following COLMAP's layout.
struct Bytes {
  std::string s;
  template <class T>
  Bytes& put(T v) {
    char b[sizeof(T)];
    std::memcpy(b, &v, sizeof(T));
    s.append(b, sizeof(T));
    return *this;
  }
  void save(const std::filesystem::path& p) const { std::ofstream(p, std::ios::binary) << s; }
};

TEST_F(ColmapTest, ReadsHandAssembledBinary) {
  std::filesystem::create_directories(dir_ / "b");
  Bytes cams;
  cams.put<uint64_t>(1).put<uint32_t>(3).put<int32_t>(4).put<uint64_t>(640).put<uint64_t>(512);
  for (double v : {435.5, 436.0, 320.5, 256.5, -0.4, 0.16, 1e-3, -2e-3}) cams.put(v);
  cams.save(dir_ / "b/cameras.bin");
  Bytes ims;
  ims.put<uint64_t>(1).put<uint32_t>(9);
  for (double v : {1.0, 0.0, 0.0, 0.0, 0.25, -0.5, 2.0}) ims.put(v);
  ims.put<uint32_t>(3);
  ims.s += std::string("80321.88.png") + '\0';
  ims.put<uint64_t>(1).put(10.5).put(20.25).put<uint64_t>(~uint64_t{0});
  ims.save(dir_ / "b/images.bin");
  const ColmapModel m = read_colmap_model(dir_ / "b");
  ASSERT_EQ(m.cameras.size(), 1u);
  EXPECT_EQ(m.cameras.at(3).model, ColmapCameraModel::kOpenCv);
  EXPECT_EQ(m.cameras.at(3).params[7], -2e-3);
  ASSERT_EQ(m.images.size(), 1u);
  EXPECT_EQ(m.images[0].name, "80321.88.png");
  EXPECT_EQ(Eigen::Vector3d(m.images[0].T_world_cam().col(3).head(3)), Eigen::Vector3d(-0.25, 0.5, -2));
  EXPECT_EQ(m.images[0].points2d[0].point3d_id, -1);
  EXPECT_TRUE(m.points.empty());  // points3D.bin is optional

  // The scene camera: OpenCV order kept, principal point moved by -0.5 to the pixel-centre origin.
  const CameraIntrinsics k = scene_camera_from_colmap(m.cameras.at(3), "cameras.bin");
  EXPECT_EQ(k.model, CameraModel::kPinhole);
  EXPECT_EQ(k.cx, 320.0);
  EXPECT_EQ(k.cy, 256.0);
  EXPECT_EQ(k.distortion, (std::vector<double>{-0.4, 0.16, 1e-3, -2e-3}));

  // Truncated: every proper prefix of images.bin is an error naming the file and a byte.
  for (size_t n : {size_t{0}, size_t{5}, size_t{12}, size_t{70}, ims.s.size() - 1}) {
    std::ofstream(dir_ / "b/images.bin", std::ios::binary) << ims.s.substr(0, n);
    testing::expect_io_error([&] { read_colmap_model(dir_ / "b"); }, {"images.bin", "byte", "truncated"});
  }
  // Trailing bytes.
  std::ofstream(dir_ / "b/images.bin", std::ios::binary) << ims.s << "x";
  testing::expect_io_error([&] { read_colmap_model(dir_ / "b"); },
                           {"images.bin: byte " + std::to_string(ims.s.size()), "unexpected bytes"});
  // Unknown model id 42 at byte 12.
  std::ofstream(dir_ / "b/images.bin", std::ios::binary) << ims.s;
  std::string bad = cams.s;
  const int32_t id42 = 42;
  std::memcpy(&bad[12], &id42, 4);
  std::ofstream(dir_ / "b/cameras.bin", std::ios::binary) << bad;
  testing::expect_io_error([&] { read_colmap_model(dir_ / "b"); },
                           {"cameras.bin: byte 12", "unknown camera model id 42"});
  // The image references camera 3; renumber the camera to 4.
  bad = cams.s;
  const uint32_t four = 4;
  std::memcpy(&bad[8], &four, 4);
  std::ofstream(dir_ / "b/cameras.bin", std::ios::binary) << bad;
  testing::expect_io_error([&] { read_colmap_model(dir_ / "b"); },
                           {"images.bin: byte 8", "references camera 3", "does not define"});
}

TEST_F(ColmapTest, MalformedTextNamesFileAndLine) {
  const auto model = write_text_model();
  const auto expect = [&](const std::string& file, const std::string& text,
                          std::initializer_list<std::string> parts) {
    write_text_model();
    write_text("txt/" + file, text);
    testing::expect_io_error([&] { read_colmap_model(model); }, parts);
  };
  expect("cameras.txt", "# c\n1 PINHOLE 8 6 500 501 4\n",
         {"cameras.txt:2:", "PINHOLE takes 4 parameters, got 3"});
  expect("cameras.txt", "1 PINHOLE 8 6\n", {"cameras.txt:1:", "takes 4 parameters, got 0"});
  expect("cameras.txt", "1 PINHOLE 8\n", {"cameras.txt:1:", "got 3 fields"});
  expect("cameras.txt", "1 PINHOLE 8 6 500 501 4 3\n2 WEIRD_MODEL 8 6 1 2 3\n",
         {"cameras.txt:2:", "unknown camera model 'WEIRD_MODEL'"});
  expect("cameras.txt", "1 PINHOLE 8 6 500 501 4 nan\n", {"cameras.txt:1:"});
  expect("images.txt", "1 1 0 0 0 1 2 3 1\n\n", {"images.txt:1:", "got 9 fields"});
  expect("images.txt", "1 1 0 0 0 1 2 3 5 a.png\n\n",
         {"images.txt:1:", "references camera 5", "does not define"});
  expect("images.txt", "\n1 1 0 0 0 1 2 3 1 a.png\n1 2\n", {"images.txt:3:", "not a multiple of 3"});
  expect("images.txt", "1 0 0 0 0 1 2 3 1 a.png\n\n", {"images.txt:1:", "quaternion norm is 0"});
  expect("images.txt", "1 1 0 0 0 1 2 3 1 a.png\n1 2 99\n", {"images.txt:1:", "references point3D 99"});
  expect("points3D.txt", "1 0 0 0 1 2 3 0.5 1\n", {"points3D.txt:1:", "got 9 fields"});
  expect("points3D.txt", "1 0 0 0 1 2 300 0.5\n", {"points3D.txt:1:", "RGB"});
  expect("points3D.txt", "1 0 0 0 1 2 3 0.5 4 0\n", {"points3D.txt:1:", "seen by image 4"});
  expect("points3D.txt", "1 0 0 0 1 2 3 0.5 1 2\n", {"points3D.txt:1:", "point2D 2 of image 1"});
  testing::expect_io_error([&] { read_colmap_model(dir_); }, {"no COLMAP model here"});
}

TEST_F(ColmapTest, CameraModelsConvertOrAreRefused) {
  ColmapCamera c;
  c.id = 2;
  c.width = 8;
  c.height = 6;
  c.model = ColmapCameraModel::kSimplePinhole;
  c.params = {400, 4, 3};
  CameraIntrinsics k = scene_camera_from_colmap(c, "f");
  EXPECT_EQ(k.fx, 400);
  EXPECT_EQ(k.fy, 400);
  EXPECT_EQ(k.cx, 3.5);
  EXPECT_EQ(k.cy, 2.5);
  EXPECT_TRUE(k.distortion.empty());
  c.model = ColmapCameraModel::kRadial;
  c.params = {400, 4, 3, 0.1, -0.02};
  EXPECT_EQ(scene_camera_from_colmap(c, "f").distortion, (std::vector<double>{0.1, -0.02, 0, 0}));
  c.model = ColmapCameraModel::kSimpleRadial;
  c.params = {400, 4, 3, 0};
  EXPECT_TRUE(scene_camera_from_colmap(c, "f").distortion.empty());  // all zero: none
  c.model = ColmapCameraModel::kOpenCvFisheye;
  c.params = {400, 401, 4, 3, 0.1, 0.2, 0.3, 0.4};
  k = scene_camera_from_colmap(c, "f");
  EXPECT_EQ(k.model, CameraModel::kEquidistant);
  EXPECT_EQ(k.distortion, (std::vector<double>{0.1, 0.2, 0.3, 0.4}));
  c.model = ColmapCameraModel::kFullOpenCv;
  c.params = {400, 401, 4, 3, 0.1, 0.2, 0.3, 0.4, 0.5, 0, 0, 0};
  EXPECT_EQ(scene_camera_from_colmap(c, "f").distortion, (std::vector<double>{0.1, 0.2, 0.3, 0.4, 0.5}));
  // Back to COLMAP and again: the same parameters.
  const ColmapCamera back = colmap_camera_from_scene(scene_camera_from_colmap(c, "f"), 2);
  EXPECT_EQ(back.model, ColmapCameraModel::kFullOpenCv);
  EXPECT_EQ(back.params, c.params);
  c.params[10] = 0.01;
  testing::expect_io_error([&] { scene_camera_from_colmap(c, "cams.txt"); },
                           {"cams.txt", "camera 2", "k4 k5 k6"});
  c.model = ColmapCameraModel::kFov;
  c.params = {400, 401, 4, 3, 0.9};
  testing::expect_io_error([&] { scene_camera_from_colmap(c, "cams.txt"); },
                           {"cams.txt", "camera 2", "FOV is not supported"});
}

Image gray(int w, int h, int bit_depth, int seed, int channels = 1) {
  Image im;
  im.width = w;
  im.height = h;
  im.bit_depth = bit_depth;
  im.channels = channels;
  for (int i = 0; i < w * h; ++i)
    for (int c = 0; c < channels; ++c) im.data.push_back(static_cast<uint16_t>((i * 37 + seed * 11) % 256));
  return im;
}

TEST_F(ColmapTest, ImportsTinyModelWithImagesAndAnchors) {
  // One camera shared by both images: rewrite cameras.txt so image 2 uses camera 1 as well.
  const auto model = write_text_model();
  write_text("txt/images.txt",
             "1 0.70710678118654757 0 0 0.70710678118654757 1 2 3 1 10.5.png\n"
             "1.5 2.5 1\n"
             "2 1 0 0 0 0 0 -5 1 sub/11.png\n"
             "\n");
  write_text("txt/points3D.txt", "1 0.5 -1.5 2.25 255 128 0 0.75 1 0\n7 1 2 3 1 2 3 -1\n");
  std::filesystem::create_directories(dir_ / "images/sub");
  const Image a = gray(8, 6, 8, 1), b = gray(8, 6, 8, 2, 3);  // b: RGB with equal channels
  write_image(dir_ / "images/10.5.png", a);
  write_image(dir_ / "images/sub/11.png", b);
  ColmapImportOptions o;
  o.model = model;
  o.images = dir_ / "images";
  o.out = dir_ / "scene";
  o.world_offset_m = Eigen::Vector3d(1, 0, 0);
  const ColmapImportReport r = import_colmap(o);
  EXPECT_EQ(r.frames, 2u);
  EXPECT_EQ(r.anchors, 2u);

  const Scene s = read_scene(o.out);
  const CameraIntrinsics& k = s.config.camera;
  EXPECT_EQ(k.fx, 500.5);
  EXPECT_EQ(k.fy, 501.25);
  EXPECT_EQ(k.cx, 3.75);
  EXPECT_EQ(k.cy, 2.625);
  EXPECT_EQ(k.bit_depth, 8);
  EXPECT_FALSE(s.config.has_lidar_map);
  EXPECT_EQ(s.config.world_offset_m, Eigen::Vector3d(1, 0, 0));
  ASSERT_EQ(s.frames.size(), 2u);
  EXPECT_EQ(s.frames[0].t_s, 10.5);
  EXPECT_EQ(s.frames[1].t_s, 11.0);
  ASSERT_EQ(s.poses.size(), 2u);
  EXPECT_LT((s.poses[0].p_world - Eigen::Vector3d(-3, 1, -3)).norm(), 1e-12);  // (-2 1 -3) - offset
  EXPECT_LT((s.poses[0].q_world_body * Eigen::Vector3d::UnitX() + Eigen::Vector3d::UnitY()).norm(), 1e-12);
  EXPECT_EQ(s.poses[1].p_world, Eigen::Vector3d(-1, 0, 5));
  EXPECT_EQ(load_frame(o.out, s, 0).data, a.data);
  EXPECT_EQ(load_frame(o.out, s, 1).data, gray(8, 6, 8, 2).data);

  // Anchor 1: seen by image 1 at depth z = (R p + t).z = 2.25 + 3 = 5.25; sigma = 0.75 px * 5.25 / f.
  ASSERT_EQ(s.anchors.size(), 2u);
  const double f = 0.5 * (500.5 + 501.25);
  EXPECT_EQ(s.anchors[0].p_world, Eigen::Vector3d(-0.5, -1.5, 2.25));
  EXPECT_NEAR(std::sqrt(s.anchors[0].cov_m2(0, 0)), 0.75 * 5.25 / f, 1e-12);
  EXPECT_EQ(s.anchors[0].cov_m2(0, 1), 0);
  // Anchor 7: no track, unknown error -> 0.5 px floor at the distance to the nearest camera centre.
  const double d = std::min((Eigen::Vector3d(1, 2, 3) - Eigen::Vector3d(-2, 1, -3)).norm(),
                            (Eigen::Vector3d(1, 2, 3) - Eigen::Vector3d(0, 0, 5)).norm());
  EXPECT_NEAR(std::sqrt(s.anchors[1].cov_m2(2, 2)), 0.5 * d / f, 1e-12);
}

TEST_F(ColmapTest, ImportRefusesBadImagesAndCameras) {
  const auto model = write_text_model();
  ColmapImportOptions o;
  o.model = model;
  o.images = dir_;
  o.out = dir_ / "scene";
  // Two cameras with different parameters.
  testing::expect_io_error([&] { import_colmap(o); }, {"cameras.txt", "cameras 1 and 2", "one camera"});
  write_text("txt/cameras.txt",
             "1 PINHOLE 8 6 500.5 501.25 4.25 3.125\n2 PINHOLE 8 6 500.5 501.25 4.25 3.125\n");
  testing::expect_io_error([&] { import_colmap(o); }, {"10.5.png", "is missing"});
  write_image(dir_ / "10.5.png", gray(8, 6, 8, 1));
  std::filesystem::create_directories(dir_ / "sub dir");
  write_image(dir_ / "sub dir/11.png", gray(8, 5, 8, 1));
  testing::expect_io_error([&] { import_colmap(o); }, {"11.png", "image is 8x5, its camera is 8x6"});
  Image colour = gray(8, 6, 8, 1, 3);
  colour.data[4] = 7;  // pixel 1, green
  write_image(dir_ / "sub dir/11.png", colour);
  testing::expect_io_error([&] { import_colmap(o); }, {"11.png", "colour image", "pixel 1, 0"});
  EXPECT_FALSE(std::filesystem::exists(o.out / "scene.yaml"));
}

// The real data: Metashape -> scene -> COLMAP (text and binary) -> scene gives the same poses and camera.
TEST_F(ColmapTest, RoundTripsRealSceneThroughColmap) {
  const auto data = testing::data_dir() / "thermitage-dunr";
  MetashapeImportOptions mo;
  mo.xml = data / "metashape/DUNR-ImgCoords-TIR.xml";
  mo.images = data / "radjpg";  // all 45 frames (8-bit) are in tests/data
  mo.out = dir_ / "scene";
  mo.calibration = data / "metashape/DUNR-GeoCamCal-TIR.xml";  // with distortion: OPENCV
  import_metashape(mo);
  const Scene original = read_scene(mo.out);
  for (bool binary : {false, true}) {
    SCOPED_TRACE(binary ? "binary" : "text");
    const auto out = dir_ / (binary ? "colmap-bin" : "colmap-txt");
    ColmapExportOptions eo;
    eo.scene = mo.out;
    eo.out = out;
    eo.binary = binary;
    const ColmapExportReport er = export_colmap(eo);
    EXPECT_EQ(er.images, 45u);
    EXPECT_EQ(er.points, 0u);  // no anchors, no map
    EXPECT_TRUE(std::filesystem::exists(out / (binary ? "sparse/0/images.bin" : "sparse/0/images.txt")));
    const ColmapModel m = read_colmap_model(out / "sparse/0");
    EXPECT_EQ(m.cameras.at(1).model, ColmapCameraModel::kOpenCv);
    // Original (not recentred) coordinates in the COLMAP model.
    EXPECT_NEAR(m.images[0].T_world_cam()(1, 3), 1005, 10);

    ColmapImportOptions io;
    io.model = out / "sparse/0";
    io.images = out / "images";
    io.out = dir_ / (binary ? "scene-bin" : "scene-txt");
    const ColmapImportReport ir = import_colmap(io);
    EXPECT_TRUE(ir.notes.empty());
    const Scene back = read_scene(io.out);
    EXPECT_EQ(back.config.world_offset_m, original.config.world_offset_m);
    const CameraIntrinsics &k0 = original.config.camera, &k1 = back.config.camera;
    EXPECT_EQ(k1.width, k0.width);
    EXPECT_EQ(k1.bit_depth, 8);
    EXPECT_NEAR(k1.fx, k0.fx, 1e-12);
    EXPECT_NEAR(k1.fy, k0.fy, 1e-12);
    EXPECT_NEAR(k1.cx, k0.cx, 1e-12);
    EXPECT_NEAR(k1.cy, k0.cy, 1e-12);
    EXPECT_EQ(k1.distortion, k0.distortion);
    ASSERT_EQ(back.poses.size(), original.poses.size());
    for (size_t i = 0; i < back.poses.size(); ++i) {
      EXPECT_EQ(back.poses[i].t_s, original.poses[i].t_s);
      EXPECT_LT((back.poses[i].p_world - original.poses[i].p_world).norm(), 1e-9);
      EXPECT_LT(
          (back.poses[i].q_world_body.toRotationMatrix() - original.poses[i].q_world_body.toRotationMatrix())
              .norm(),
          1e-9);
    }
    EXPECT_EQ(load_frame(io.out, back, 3).data, load_frame(mo.out, original, 3).data);
  }
}

}  // namespace
}  // namespace litgs::io
