// The front end on whole scenes with hard or bad input (named cases): each gives a clear error or an empty
// result with counts, never a crash or a non-finite point. And the easy case, for contrast: a translating
// camera over a textured plane gives points on the plane.
#include <gtest/gtest.h>

#include <algorithm>

#include "host/frontend/frontend.h"
#include "io/error.h"
#include "io/sfm_files.h"
#include "tests/frontend/plane_scene.h"
#include "tests/io/io_test.h"

namespace litgs::host::frontend {
namespace {

using testing::plane_view;
using testing::PlaneCamera;

class FrontendScene : public testing::TempDirTest {
 protected:
  FrontendOptions options() const {
    FrontendOptions o;
    o.features.max_keypoints = 1500;
    o.pairs = parse_pairs("exhaustive");
    o.threads = 2;
    return o;
  }
  static void expect_finite(const FrontendResult& r) {
    for (const auto& p : r.data.points) {
      EXPECT_TRUE(p.xyz.allFinite());
      EXPECT_TRUE(std::isfinite(p.error_px));
    }
  }
  PlaneCamera k_;
};

TEST_F(FrontendScene, TranslationOverATexturedPlaneGivesPointsOnThePlane) {
  std::vector<Eigen::Isometry3d> poses;
  for (int i = 0; i < 4; ++i) poses.push_back(plane_view({0.4 * i, 0.05 * i, 0}));
  testing::write_rendered_plane_scene(dir_, k_, poses);
  const FrontendResult r = run_frontend(dir_, options());
  EXPECT_EQ(r.summary.pairs_tried, 6u);
  EXPECT_GE(r.summary.pairs_verified, 5u);
  ASSERT_GT(r.summary.points, 200u);
  EXPECT_LT(r.summary.mean_error_px, 1.0);
  expect_finite(r);
  size_t off_plane = 0;
  for (const auto& p : r.data.points) off_plane += std::abs(p.xyz.z() - testing::kPlaneZ) > 0.05;
  EXPECT_LT(off_plane, r.data.points.size() / 50) << "more than 2% of the points are 5 cm off the plane";
  // Written and read back.
  write_frontend(dir_, r);
  const io::SfmData back = io::read_sfm(dir_ / "sfm");
  EXPECT_EQ(back.points.size(), r.data.points.size());
  EXPECT_EQ(back.tracks.size(), r.data.tracks.size());
  EXPECT_TRUE(std::filesystem::exists(dir_ / "sfm/frontend.json"));
}

// One frame smeared by motion (a 15-pixel horizontal box blur, as a fast pan would): it gives far fewer
// keypoints than the sharp frames; the sharp frames still match and triangulate points on the plane, and
// nothing is non-finite.
TEST_F(FrontendScene, MotionBlurredFrame) {
  std::vector<io::Image> images;
  std::vector<Eigen::Isometry3d> poses;
  for (int i = 0; i < 4; ++i) {
    poses.push_back(plane_view({0.4 * i, 0.05 * i, 0}));
    images.push_back(testing::render_plane(k_, poses.back()));
  }
  io::Image& blurred = images[2];
  const io::Image sharp = blurred;
  for (int y = 0; y < blurred.height; ++y)
    for (int x = 0; x < blurred.width; ++x) {
      int sum = 0, n = 0;
      for (int d = -7; d <= 7; ++d) {
        const int xx = std::clamp(x + d, 0, blurred.width - 1);
        sum += sharp.data[static_cast<size_t>(y) * blurred.width + xx];
        ++n;
      }
      blurred.data[static_cast<size_t>(y) * blurred.width + x] = static_cast<uint16_t>(sum / n);
    }
  testing::write_plane_scene(dir_, k_, poses, images);
  const FrontendResult r = run_frontend(dir_, options());
  expect_finite(r);
  const size_t blurred_keypoints = r.data.images[2].keypoints.size();
  EXPECT_LT(blurred_keypoints, r.data.images[0].keypoints.size() / 2);
  EXPECT_GT(r.summary.points, 100u);
  size_t off_plane = 0;
  for (const auto& p : r.data.points) off_plane += std::abs(p.xyz.z() - testing::kPlaneZ) > 0.05;
  EXPECT_LT(off_plane, r.data.points.size() / 20);
}

TEST_F(FrontendScene, UniformFrames) {
  std::vector<io::Image> images;
  std::vector<Eigen::Isometry3d> poses;
  for (int i = 0; i < 3; ++i) {
    io::Image img = testing::render_plane(k_, plane_view({0, 0, 0}));
    std::fill(img.data.begin(), img.data.end(), static_cast<uint16_t>(40 * (i + 1)));  // no texture at all
    images.push_back(img);
    poses.push_back(plane_view({0.3 * i, 0, 0}));
  }
  testing::write_plane_scene(dir_, k_, poses, images);
  const FrontendResult r = run_frontend(dir_, options());
  EXPECT_EQ(r.summary.images, 3u);
  EXPECT_EQ(r.summary.frozen, 0u);
  EXPECT_EQ(r.summary.uniform, 3u);
  EXPECT_EQ(r.summary.keypoints, 0u);
  EXPECT_EQ(r.summary.pairs_tried, 3u);
  EXPECT_EQ(r.summary.pairs_verified, 0u);
  EXPECT_EQ(r.summary.points, 0u);
  ASSERT_FALSE(r.summary.notes.empty());
  EXPECT_NE(r.summary.notes[0].find("without any contrast"), std::string::npos);
  write_frontend(dir_, r);  // an empty result is written like any other
  EXPECT_TRUE(io::read_sfm(dir_ / "sfm").points.empty());
}

TEST_F(FrontendScene, FrozenRun) {
  // Frames 1..3 repeat frame 0 (the camera froze while it moved on), frame 4 is live again.
  std::vector<Eigen::Isometry3d> poses;
  std::vector<io::Image> images;
  for (int i = 0; i < 5; ++i) {
    poses.push_back(plane_view({0.3 * i, 0, 0}));
    images.push_back(testing::render_plane(k_, poses[i < 4 ? 0 : 4]));
  }
  testing::write_plane_scene(dir_, k_, poses, images);
  const FrontendResult r = run_frontend(dir_, options());
  EXPECT_EQ(r.summary.frozen, 3u);
  EXPECT_EQ(r.frozen_frames, (std::vector<std::string>{"2.png", "3.png", "4.png"}));
  EXPECT_EQ(r.summary.pairs_tried, 1u);  // frames 0 and 4 only
  for (size_t i = 1; i < 4; ++i) {
    EXPECT_TRUE(r.data.images[i].frozen);
    EXPECT_TRUE(r.data.images[i].keypoints.empty());
  }
  expect_finite(r);
}

TEST_F(FrontendScene, TwoIdenticalFrames) {
  const std::vector<Eigen::Isometry3d> poses = {plane_view({0, 0, 0}), plane_view({0.5, 0, 0})};
  const io::Image img = testing::render_plane(k_, poses[0]);
  testing::write_plane_scene(dir_, k_, poses, {img, img});
  const FrontendResult r = run_frontend(dir_, options());
  EXPECT_EQ(r.summary.frozen, 1u);
  EXPECT_EQ(r.summary.pairs_tried, 0u);
  EXPECT_EQ(r.summary.points, 0u);
  EXPECT_GT(r.summary.keypoints, 100u);  // the kept frame still has its keypoints
}

TEST_F(FrontendScene, PureRotationTriangulatesNothing) {
  const std::vector<Eigen::Isometry3d> poses = {plane_view({0, 0, 0}, 0), plane_view({0, 0, 0}, 6),
                                                plane_view({0, 0, 0}, 12)};
  testing::write_rendered_plane_scene(dir_, k_, poses);
  const FrontendResult r = run_frontend(dir_, options());
  EXPECT_GE(r.summary.pairs_verified, 2u);  // the matches are good ...
  EXPECT_GT(r.summary.tracks, 100u);
  EXPECT_EQ(r.summary.points, 0u);               // ... but without a baseline there is no depth
  EXPECT_GT(r.summary.rejected_no_angle, 100u);  // three-view tracks: no angle; two-view ones: too few views
  EXPECT_EQ(r.summary.rejected_no_angle + r.summary.rejected_few_views, r.summary.tracks);
}

TEST_F(FrontendScene, WrongImageSize) {
  const std::vector<Eigen::Isometry3d> poses = {plane_view({0, 0, 0}), plane_view({0.5, 0, 0})};
  testing::write_rendered_plane_scene(dir_, k_, poses);
  PlaneCamera small = k_;
  small.width = 200;
  io::write_image(dir_ / "thermal/2.png", testing::render_plane(small, poses[1]));
  testing::expect_io_error([&] { run_frontend(dir_, options()); }, {"2.png", "200"});
  EXPECT_FALSE(std::filesystem::exists(dir_ / "sfm"));
}

TEST_F(FrontendScene, Constant16BitImages) {
  std::vector<io::Image> images;
  std::vector<Eigen::Isometry3d> poses;
  for (int i = 0; i < 3; ++i) {
    io::Image img = testing::render_plane(k_, plane_view({0, 0, 0}), 16);
    std::fill(img.data.begin(), img.data.end(), uint16_t{3500});
    images.push_back(img);
    poses.push_back(plane_view({0.3 * i, 0, 0}));
  }
  testing::write_plane_scene(dir_, k_, poses, images);
  const FrontendResult r = run_frontend(dir_, options());
  EXPECT_EQ(r.summary.frozen, 2u);   // identical frames
  EXPECT_EQ(r.summary.uniform, 1u);  // the one kept has no contrast
  EXPECT_EQ(r.summary.keypoints, 0u);
  EXPECT_EQ(r.summary.points, 0u);
}

TEST_F(FrontendScene, BadOptionsAreNamed) {
  FrontendOptions o = options();
  o.features.max_keypoints = 0;
  try {
    run_frontend(dir_, o);
    ADD_FAILURE() << "expected invalid_argument";
  } catch (const std::invalid_argument& e) {
    EXPECT_NE(std::string(e.what()).find("max_keypoints"), std::string::npos) << e.what();
  }
}

}  // namespace
}  // namespace litgs::host::frontend

namespace litgs::host::frontend {
namespace {

class SfmFiles : public testing::TempDirTest {};

TEST_F(SfmFiles, RoundTripAndErrorsNameFileAndLine) {
  io::SfmData d;
  d.images = {{"thermal/1.png", false, {{1.5f, 2.25f, 3, 45}, {7, 8, 2, -1}}},
              {"thermal/2.png", true, {}},
              {"thermal/3.png", false, {{4, 5, 6, 7}}}};
  d.pairs = {{0, 2, {{0, 0, true}, {1, 0, false}}}};
  d.tracks = {{{{0, 0}, {2, 0}}, 0}};
  d.points = {{Eigen::Vector3d(0.1, -2, 1e3 / 3), 0.25, {{0, 0}, {2, 0}}}};
  write_sfm(dir_ / "sfm", d, "{}");
  const io::SfmData back = io::read_sfm(dir_ / "sfm");
  ASSERT_EQ(back.images.size(), 3u);
  EXPECT_TRUE(back.images[1].frozen);
  EXPECT_EQ(back.images[0].keypoints[0].y, 2.25f);
  ASSERT_EQ(back.pairs.size(), 1u);
  EXPECT_FALSE(back.pairs[0].matches[1].inlier);
  EXPECT_EQ(back.tracks[0].observations, d.tracks[0].observations);
  EXPECT_EQ(back.points[0].xyz, d.points[0].xyz);  // exact round trip
  // A point that names a keypoint image 2 does not have.
  std::ofstream(dir_ / "sfm/points.txt") << "# header\n0 0 0 1 0.5 2 0 0 2 1\n";
  testing::expect_io_error([&] { io::read_sfm(dir_ / "sfm"); }, {"points.txt", ":2", "keypoint"});
  d.points[0].xyz.x() = NAN;
  EXPECT_THROW(write_sfm(dir_ / "sfm", d, "{}"), std::invalid_argument);
}

}  // namespace
}  // namespace litgs::host::frontend
