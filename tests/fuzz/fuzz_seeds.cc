// Writes the generated part of the seed corpora (tests/fuzz/corpus/<target>/gen-*): small valid files
// from the io writers. Not run in CI; rerun by hand after a format change:
//   build-fuzz/litgs_fuzz_seeds tests/fuzz/corpus   (executables land in the build directory's root)
// The ROS bags need a build with rosbag_storage (ci/setup). The real-data seeds (TUM, M2DGR calibration,
// Metashape XML, DUNR JPEG) are copies of files in tests/data (licences and provenance there).
#include <cmath>
#include <filesystem>
#include <fstream>
#include <iostream>
#include <random>

#include "host/train/checkpoint.h"
#include "io/file_bytes.h"
#include "io/gaussian_ply.h"
#include "io/image.h"
#include "io/pcd.h"
#include "io/ros_bag.h"
#include "io/scene_yaml.h"
#include "tests/fuzz/fuzz_colmap.h"

namespace fs = std::filesystem;
using namespace litgs;

namespace {

void put(const fs::path& path, const std::string& bytes) {
  fs::create_directories(path.parent_path());
  std::ofstream(path, std::ios::binary) << bytes;
}

kernels::GaussianModel small_model(uint32_t channels, uint32_t degree, size_t n) {
  kernels::GaussianModel m;
  m.channels = channels;
  m.sh_degree = degree;
  m.resize(n);
  std::mt19937 rng(1);
  std::uniform_real_distribution<float> u(-1, 1);
  for (auto* v : {&m.means, &m.log_scales, &m.quats, &m.opacity_logits, &m.sh})
    for (auto& x : *v) x = u(rng);
  return m;
}

}  // namespace

int main(int argc, char** argv) {
  if (argc != 2) {
    std::cerr << "usage: litgs_fuzz_seeds CORPUS_DIR\n";
    return 2;
  }
  const fs::path out = argv[1];
  const fs::path tmp = fs::temp_directory_path() / ("litgs-fuzz-seeds-" + std::to_string(::getpid()));
  fs::create_directories(tmp);
  for (const char* d : {"png", "tiff", "pcd", "ply_points", "gaussian_ply", "scene_yaml", "checkpoint"})
    fs::create_directories(out / d);

  // Images: 8-bit gray, 16-bit gray, 8-bit RGB.
  for (auto [c, depth] : {std::pair{1, 8}, std::pair{1, 16}, std::pair{3, 8}}) {
    io::Image im;
    im.width = 5;
    im.height = 3;
    im.channels = c;
    im.bit_depth = depth;
    for (int i = 0; i < 15 * c; ++i)
      im.data.push_back(static_cast<uint16_t>((i * 37) % (depth == 8 ? 256 : 65536)));
    const std::string stem = "gen-c" + std::to_string(c) + "-" + std::to_string(depth);
    io::write_png(out / "png" / (stem + ".png"), im);
    io::write_tiff(out / "tiff" / (stem + ".tif"), im);
  }

  // PCD: binary (writer), ascii and binary_compressed-free header variants by hand.
  io::PointCloud cloud;
  for (int i = 0; i < 6; ++i) cloud.positions.push_back({i * 0.5, -i * 0.25, 3.0});
  cloud.intensity.assign(6, 7.f);
  io::write_pcd(out / "pcd" / "gen-binary.pcd", cloud);
  io::write_pcd(out / "pcd" / "gen-binary-f8.pcd", cloud, {.double_positions = true});
  put(out / "pcd" / "gen-ascii.pcd",
      "# .PCD v0.7\nVERSION 0.7\nFIELDS x y z intensity\nSIZE 4 4 4 4\nTYPE F F F F\nCOUNT 1 1 1 1\n"
      "WIDTH 2\nHEIGHT 1\nVIEWPOINT 0 0 0 1 0 0 0\nPOINTS 2\nDATA ascii\n1 2 3 4\n5 6 7 8\n");

  // PLY points: ascii and binary little endian.
  put(out / "ply_points" / "gen-ascii.ply",
      "ply\nformat ascii 1.0\nelement vertex 2\nproperty float x\nproperty float y\nproperty float z\n"
      "property uchar red\nproperty uchar green\nproperty uchar blue\nend_header\n1 2 3 255 0 0\n4 5 6 0 255 "
      "0\n");
  {
    std::string b =
        "ply\nformat binary_little_endian 1.0\nelement vertex 2\nproperty double x\nproperty double y\n"
        "property double z\nproperty float intensity\nend_header\n";
    for (int i = 0; i < 2; ++i) {
      const double xyz[3] = {i + 0.5, 2.0 * i, -1.0};
      const float f = 3.f * static_cast<float>(i);
      b.append(reinterpret_cast<const char*>(xyz), sizeof xyz);
      b.append(reinterpret_cast<const char*>(&f), sizeof f);
    }
    put(out / "ply_points" / "gen-binary.ply", b);
  }

  // 3DGS PLY: thermal degree 1 and RGB degree 0.
  io::write_gaussian_ply(out / "gaussian_ply" / "gen-c1-d1.ply", small_model(1, 1, 2));
  io::write_gaussian_ply(out / "gaussian_ply" / "gen-c3-d0.ply", small_model(3, 0, 2));

  // scene.yaml.
  io::SceneConfig c;
  c.camera.width = 640;
  c.camera.height = 512;
  c.camera.fx = c.camera.fy = 435.8;
  c.camera.cx = 320;
  c.camera.cy = 256;
  c.camera.distortion = {0.1, 0.01, 0, 0};
  io::write_scene_yaml(out / "scene_yaml" / "gen.yaml", c);

  // COLMAP: one seed per file (first byte selects it, see fuzz_colmap.h), text and binary.
  for (bool binary : {false, true}) {
    const fs::path dir = tmp / (binary ? "bin" : "txt");
    io::write_colmap_model(dir, fuzz::small_colmap_model(), binary);
    const char* ext = binary ? ".bin" : ".txt";
    const char* stems[3] = {"cameras", "images", "points3D"};
    for (int i = 0; i < 3; ++i)
      put(out / (binary ? "colmap_binary" : "colmap_text") / (std::string("gen-") + stems[i]),
          std::string(1, static_cast<char>(i)) + io::read_file_bytes(dir / (std::string(stems[i]) + ext)));
  }

  // Checkpoint: two Gaussians, non-zero moments.
  host::Checkpoint ck;
  ck.iteration = 7;
  ck.view_order = {2, 0, 1};
  ck.order_position = 1;
  ck.rng_state = "5489";
  ck.state = kernels::TrainingState::fresh(small_model(1, 1, 2));
  ck.state.exp_avg[0].assign(ck.state.exp_avg[0].size(), 0.5f);
  ck.state.denom = {1, 2};
  host::write_checkpoint(out / "checkpoint" / "gen.ckpt", ck);

  // ROS bags: the four message types fuzz_ros_bag reads (/thermal: mono8 and rgb16 images, /lidar: clouds
  // with and without intensity, one point NaN, /imu, /odom), with uncompressed, bz2 and lz4 chunks.
  if (!io::ros_bag_writer_available()) {
    std::cerr << "litgs_fuzz_seeds: this build cannot write ROS bags (ci/setup); ros_bag seeds not written\n";
    return 1;
  }
  fs::create_directories(out / "ros_bag");
  for (auto [name, compression] :
       {std::pair{"none", io::RosBagCompression::kNone}, std::pair{"bz2", io::RosBagCompression::kBz2},
        std::pair{"lz4", io::RosBagCompression::kLz4}}) {
    io::RosBagWriter w(out / "ros_bag" / ("gen-" + std::string(name) + ".bag"), compression);
    for (auto [channels, depth] : {std::pair{1, 8}, std::pair{3, 16}}) {
      io::Image im;
      im.width = 3;
      im.height = 2;
      im.channels = channels;
      im.bit_depth = depth;
      for (int i = 0; i < 6 * channels; ++i)
        im.data.push_back(static_cast<uint16_t>(i * 41 % (depth == 8 ? 256 : 65536)));
      w.image("/thermal", 10.0 + channels, im);
    }
    io::PointCloud pc;
    pc.positions = {{1, 2, 3}, {NAN, 0, 0}, {-4, 5, 0.5}};
    w.cloud("/lidar", 10.5, pc);
    pc.intensity = {1, 2, 3};
    w.cloud("/lidar", 11.5, pc);
    for (int i = 0; i < 2; ++i) {
      w.imu("/imu", {10.0 + i, {0.1, -0.2, 0.3 * i}, {0, 9.8, 0.1}});
      io::TumPose p;
      p.t_s = 10.25 + i;
      p.p_world = {i * 1.0, 2.0, -3.0};
      w.odom("/odom", p);
    }
    w.close();
  }

  fs::remove_all(tmp);
  return 0;
}
