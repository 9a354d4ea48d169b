// The co-visibility mask (host/eval/covisibility.h) on scenes whose answer is known in closed form: a wall
// seen from two cameras side by side, an occluder, sky; and the masked PSNR and mask downscaling.
#include <gtest/gtest.h>

#include <cmath>
#include <filesystem>
#include <fstream>

#include "host/eval/covisibility.h"
#include "host/synth/synth.h"
#include "io/image.h"
#include "io/scene.h"
#include "kernels/loss/loss_reference.h"

namespace litgs::host {
namespace {

namespace fs = std::filesystem;

// A 64x48 camera looking along +z from (x, 0, 0); fx = fy = 32, principal point at the centre.
kernels::SplatCamera camera_at(double x) {
  kernels::SplatCamera c;
  c.fx = c.fy = 32;
  c.cx = 32;
  c.cy = 24;
  c.width = 64;
  c.height = 48;
  c.t_cam_world = {-x, 0, 0};  // p_cam = p_world - (x, 0, 0)
  return c;
}

DepthView wall_view(double x, double depth_m) {
  DepthView v{camera_at(x), {}};
  v.depth_m.assign(64 * 48, static_cast<float>(depth_m));
  return v;
}

TEST(Covisibility, AWallSeenFromTwoCamerasSideBySide) {
  // The wall at z = 5 m. The other camera, 1 m to the right, sees world x in [-4, 6]; the target's pixel
  // column i looks at x = 5 (i + 0.5 - 32) / 32, left of -4 for i <= 5: those six columns are not covisible.
  const std::vector<uint8_t> mask = covisible_pixels(wall_view(0, 5), {wall_view(1, 5)});
  for (int j = 0; j < 48; ++j)
    for (int i = 0; i < 64; ++i) ASSERT_EQ(mask[j * 64 + i], i <= 5 ? 0 : 1) << "pixel " << i << ", " << j;
  // Seen by the target itself, every pixel is covisible; by nothing, none is.
  const std::vector<uint8_t> self = covisible_pixels(wall_view(0, 5), {wall_view(0, 5)});
  EXPECT_EQ(std::count(self.begin(), self.end(), 1), 64 * 48);
  const std::vector<uint8_t> none = covisible_pixels(wall_view(0, 5), {});
  EXPECT_EQ(std::count(none.begin(), none.end(), 1), 0);
}

TEST(Covisibility, AnOccluderInTheOtherViewHidesTheWallBehindIt) {
  // The other camera (same place) sees a near object at 2 m over its left half: the wall behind it is hidden.
  DepthView other = wall_view(0, 5);
  for (int j = 0; j < 48; ++j)
    for (int i = 0; i < 32; ++i) other.depth_m[j * 64 + i] = 2.0f;
  const std::vector<uint8_t> mask = covisible_pixels(wall_view(0, 5), {other});
  for (int j = 0; j < 48; ++j)
    for (int i = 0; i < 64; ++i) {
      // Columns 31 and 32 straddle the edge: one of the four pixels around each projection is the wall.
      if (i == 31) continue;
      ASSERT_EQ(mask[j * 64 + i], i < 31 ? 0 : 1) << "pixel " << i << ", " << j;
    }
  // A second view that sees the whole wall restores it.
  const std::vector<uint8_t> both = covisible_pixels(wall_view(0, 5), {other, wall_view(0.5, 5)});
  EXPECT_EQ(both[10 * 64 + 10], 1);
}

TEST(Covisibility, SkyCountsWhereAnotherViewLooksThatWayAndSeesSky) {
  DepthView sky = wall_view(0, 0);
  // A camera far to the side, same orientation, also seeing sky: the same directions, all covisible.
  const std::vector<uint8_t> same = covisible_pixels(sky, {wall_view(100, 0)});
  EXPECT_EQ(std::count(same.begin(), same.end(), 1), 64 * 48);
  // The same camera seeing a wall there: the target's sky is not what it saw.
  const std::vector<uint8_t> wall = covisible_pixels(sky, {wall_view(0, 5)});
  EXPECT_EQ(std::count(wall.begin(), wall.end(), 1), 0);
  // A camera looking the other way (rotated 180 degrees about y) sees none of those directions.
  DepthView back = wall_view(0, 0);
  back.camera.R_cam_world = glm::dmat3(-1, 0, 0, 0, 1, 0, 0, 0, -1);
  const std::vector<uint8_t> behind = covisible_pixels(sky, {back});
  EXPECT_EQ(std::count(behind.begin(), behind.end(), 1), 0);
}

TEST(Covisibility, WrongSizesAreErrors) {
  DepthView bad = wall_view(0, 5);
  bad.depth_m.pop_back();
  EXPECT_THROW(covisible_pixels(bad, {wall_view(0, 5)}), std::invalid_argument);
  EXPECT_THROW(covisible_pixels(wall_view(0, 5), {bad}), std::invalid_argument);
  EXPECT_THROW(downscale_mask({1, 0, 1}, 2, 2, 1, 1), std::invalid_argument);
  EXPECT_THROW(masked_psnr(std::vector<float>(4), std::vector<float>(4), {1, 1}), std::invalid_argument);
}

TEST(Covisibility, DownscaleKeepsAPixelWhenHalfItsInputIs) {
  // 4x2 -> 2x1: the left output pixel covers inputs (0,0) (1,0) (0,1) (1,1), the right one the others.
  const std::vector<uint8_t> mask = {1, 0, 1, 0,  //
                                     1, 0, 0, 0};
  EXPECT_EQ(downscale_mask(mask, 4, 2, 2, 1), (std::vector<uint8_t>{1, 0}));  // 2 of 4, 1 of 4
  EXPECT_EQ(downscale_mask(mask, 4, 2, 4, 2), mask);                          // same size: unchanged
}

TEST(Covisibility, MaskedPsnrCountsOnlyThePixelsOfTheMask) {
  const std::vector<float> target = {0.5f, 0.5f, 0.5f, 0.5f};
  const std::vector<float> render = {0.6f, 0.4f, 0.5f, 0.0f};  // the last pixel is far off
  EXPECT_NEAR(masked_psnr(render, target, {1, 1, 1, 1}), kernels::psnr(render, target), 1e-9);
  // Without the last pixel: MSE (0.01 + 0.01 + 0) / 3.
  EXPECT_NEAR(masked_psnr(render, target, {1, 1, 1, 0}), 10 * std::log10(3 / 0.02), 1e-5);
  EXPECT_TRUE(std::isnan(masked_psnr(render, target, {0, 0, 0, 0})));
}

// A small synthetic scene: gt/depth matches the true poses, and what eval reads from it.
class CovisibilityScene : public ::testing::Test {
 protected:
  static void SetUpTestSuite() {
    dir_ = fs::temp_directory_path() / ("litgs_covis_" + std::to_string(::getpid()));
    fs::remove_all(dir_);
    synth::SynthOptions o;
    o.preset = "facade";
    o.frames = 16;
    o.width = 80;
    o.height = 64;
    o.out = dir_;
    synth::generate_synthetic_scene(o);
  }
  static void TearDownTestSuite() { fs::remove_all(dir_); }
  static TrainingData data() {
    TrainingDataOptions o;
    o.holdout_every = 8;
    return load_training_data(dir_, o);
  }
  static fs::path dir_;
};
fs::path CovisibilityScene::dir_;

TEST_F(CovisibilityScene, SyntheticDepthPutsTheLidarMapOnTheSurface) {
  // Every true map point a frame's camera sees in front of it lies at the depth gt/depth holds there (or
  // behind a nearer surface): the depth and the poses agree.
  const io::Scene scene = io::read_scene(dir_);
  const TrainingData d = data();
  TrainingDataOptions native = d.options;
  native.true_poses = true;
  const kernels::SplatCamera c = training_camera(dir_, scene, d.views[3].t_s, native);
  const io::Image depth = io::read_image(dir_ / "gt/depth" / d.views[3].name);
  ASSERT_EQ(depth.width, 80);
  ASSERT_EQ(depth.bit_depth, 16);
  size_t on_surface = 0, in_front = 0;  // points behind a nearer surface (occluded) are allowed
  for (const Eigen::Vector3d& p : scene.gt->map->positions) {
    Eigen::Vector3d q;
    for (int r = 0; r < 3; ++r)
      q[r] = c.R_cam_world[0][r] * p.x() + c.R_cam_world[1][r] * p.y() + c.R_cam_world[2][r] * p.z() +
             c.t_cam_world[r];
    if (q.z() < 0.5) continue;
    const double u = c.fx * q.x() / q.z() + c.cx - 0.5, v = c.fy * q.y() / q.z() + c.cy - 0.5;
    const long i = std::lround(u), j = std::lround(v);
    if (i < 1 || j < 1 || i >= 79 || j >= 63) continue;
    const double z = depth.at(static_cast<int>(i), static_cast<int>(j)) * 1e-3;
    if (std::abs(z - q.z()) < 0.05 * q.z())
      ++on_surface;
    else if (z > q.z())
      ++in_front;
  }
  EXPECT_GT(on_surface, 1000u);
  EXPECT_LT(in_front, on_surface / 50) << "map points in front of the true surface: depth or poses are off";
}

TEST_F(CovisibilityScene, HeldOutMasksFromTheScene) {
  const io::Scene scene = io::read_scene(dir_);
  const TrainingData d = data();
  const HeldoutCovisibility c = heldout_covisibility(dir_, scene, d);
  ASSERT_TRUE(c.unavailable.empty()) << c.unavailable;
  ASSERT_EQ(c.masks.size(), d.views.size());
  for (size_t v = 0; v < d.views.size(); ++v) {
    if (!d.views[v].heldout) {
      EXPECT_TRUE(c.masks[v].empty());
      continue;
    }
    ASSERT_EQ(c.masks[v].size(), static_cast<size_t>(d.width) * d.height);
    const double share = static_cast<double>(std::count(c.masks[v].begin(), c.masks[v].end(), 1)) /
                         static_cast<double>(c.masks[v].size());
    // The facade moves sideways: most of a held-out view is seen by its neighbours, not all of the first.
    EXPECT_GT(share, 0.5) << d.views[v].name;
    if (v == 0) {
      EXPECT_LT(share, 1.0) << "the first frame looks past the start of the trajectory";
    }
  }
}

TEST_F(CovisibilityScene, MissingOrDamagedDepthSaysWhy) {
  const io::Scene scene = io::read_scene(dir_);
  const TrainingData d = data();
  const fs::path file = dir_ / "gt/depth" / d.views[5].name;
  const fs::path kept = dir_ / "kept.png";
  fs::rename(file, kept);
  EXPECT_NE(heldout_covisibility(dir_, scene, d).unavailable.find(d.views[5].name), std::string::npos);
  std::ofstream(file) << "not a png";
  const HeldoutCovisibility damaged = heldout_covisibility(dir_, scene, d);
  EXPECT_TRUE(damaged.masks.empty());
  EXPECT_NE(damaged.unavailable.find(d.views[5].name), std::string::npos) << damaged.unavailable;
  fs::remove(file);
  io::Image small;
  small.width = 8;
  small.height = 8;
  small.bit_depth = 16;
  small.data.assign(64, 1000);
  io::write_image(file, small);
  const HeldoutCovisibility wrong = heldout_covisibility(dir_, scene, d);
  EXPECT_NE(wrong.unavailable.find("8x8"), std::string::npos) << wrong.unavailable;
  fs::remove(file);
  fs::rename(kept, file);
  fs::rename(dir_ / "gt/depth", dir_ / "depth-kept");
  EXPECT_EQ(heldout_covisibility(dir_, scene, d).unavailable, "the scene has no gt/depth/");
  fs::rename(dir_ / "depth-kept", dir_ / "gt/depth");
}

}  // namespace
}  // namespace litgs::host
