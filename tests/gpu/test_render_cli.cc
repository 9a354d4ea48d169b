// `litgs-engine render` end to end: a 3DGS PLY in, PNGs out, device and CPU reference agreeing; bad input
// gets a clear message and a non-zero exit.
#include <gtest/gtest.h>
#include <unistd.h>

#include <cstdio>
#include <filesystem>
#include <fstream>
#include <string>

#include "engine_cli.h"
#include "io/gaussian_ply.h"
#include "io/image.h"
#include "splat_scenes.h"

namespace litgs {
namespace {

namespace fs = std::filesystem;

using testing::CommandResult;
using testing::run_engine;

class RenderCli : public ::testing::Test {
 protected:
  void SetUp() override {
    dir_ = fs::temp_directory_path() / ("litgs-render-cli-" + std::to_string(::getpid()));
    fs::create_directories(dir_);
    io::write_gaussian_ply(dir_ / "model.ply", testing::random_scene(300, 1, 3, 5));
    std::ofstream(dir_ / "camera.json")
        << R"({"width": 48, "height": 40, "fx": 48, "fy": 48, "cx": 24, "cy": 20,
      "q_cam_world": [1, 0, 0, 0], "t_cam_world": [0, 0, 0]})";
  }
  void TearDown() override { fs::remove_all(dir_); }
  std::string path(const char* name) const { return (dir_ / name).string(); }
  fs::path dir_;
};

TEST_F(RenderCli, DeviceAndReferenceAgree) {
  const CommandResult device =
      run_engine("render --model " + path("model.ply") + " --camera " + path("camera.json") + " --out " +
                 path("device.png") + " --depth " + path("depth.png") + " --alpha " + path("alpha.png") +
                 " --bit-depth 16");
  ASSERT_EQ(device.status, 0) << device.output;
  const CommandResult reference = run_engine(
      "render --reference --model " + path("model.ply") + " --pose 1 0 0 0 0 0 0" +
      " --intrinsics 48 48 24 20 --width 48 --height 40 --out " + path("reference.png") + " --bit-depth 16");
  ASSERT_EQ(reference.status, 0) << reference.output;
  EXPECT_EQ(device.output.find("validation"), std::string::npos) << device.output;
  const io::Image a = io::read_image(path("device.png")), b = io::read_image(path("reference.png"));
  ASSERT_EQ(a.width, 48);
  ASSERT_EQ(a.channels, 1);
  ASSERT_EQ(a.data.size(), b.data.size());
  size_t close = 0, lit = 0;
  for (size_t i = 0; i < a.data.size(); ++i) {
    close += std::abs(int(a.data[i]) - int(b.data[i])) <= 2;  // 16-bit units: 3e-5
    lit += a.data[i] > 0;
  }
  EXPECT_GE(close, a.data.size() * 99 / 100);
  EXPECT_GT(lit, a.data.size() / 2) << "the random scene fills the view";
  EXPECT_EQ(io::read_image(path("depth.png")).bit_depth, 16);
  EXPECT_EQ(io::read_image(path("alpha.png")).bit_depth, 8);
}

TEST_F(RenderCli, MissingCameraIsAClearError) {
  const CommandResult r = run_engine("render --model " + path("model.ply") + " --out " + path("x.png"));
  EXPECT_NE(r.status, 0);
  EXPECT_NE(r.output.find("--camera"), std::string::npos) << r.output;
  EXPECT_FALSE(fs::exists(path("x.png")));
}

TEST_F(RenderCli, CorruptModelIsAClearError) {
  std::ofstream(path("bad.ply"))
      << "ply\nformat binary_little_endian 1.0\nelement vertex 10\nproperty float x\n";
  const CommandResult r = run_engine("render --model " + path("bad.ply") + " --camera " +
                                     path("camera.json") + " --out " + path("x.png"));
  EXPECT_NE(r.status, 0);
  EXPECT_NE(r.output.find("bad.ply"), std::string::npos) << r.output;
}

}  // namespace
}  // namespace litgs
