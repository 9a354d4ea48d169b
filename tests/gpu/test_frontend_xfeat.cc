// The front end with XFeat on the device (`match --features xfeat`, host/nn/xfeat_features.h), validation
// layer on: a camera translating over a textured plane gives verified matches and points on the plane (the
// frames are 320x240, not a multiple of 32: resized as XFeat does, keypoints mapped back); a uniform frame
// gives no keypoints and no NaN; xfeat without a detector, and the mnn matcher on bit strings, are clear
// errors. The same plane matched by LighterGlue.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdio>

#include "host/frontend/frontend.h"
#include "host/frontend/matching.h"
#include "host/nn/xfeat_features.h"
#include "tests/frontend/plane_scene.h"
#include "tests/io/io_test.h"

namespace litgs::host::frontend {
namespace {

class FrontendXfeat : public testing::TempDirTest {
 protected:
  static FrontendOptions options() {
    FrontendOptions o;
    o.features.type = FeatureType::kXfeat;
    o.features.max_keypoints = 1500;
    o.match.matcher = Matcher::kMnn;
    o.pairs = parse_pairs("exhaustive");
    o.threads = 2;
    return nn::with_learned_detector(o);
  }
};

TEST_F(FrontendXfeat, TranslationOverATexturedPlaneGivesPointsOnThePlane) {
  std::vector<Eigen::Isometry3d> poses;
  for (int i = 0; i < 4; ++i) poses.push_back(testing::plane_view({0.4 * i, 0.05 * i, 0}));
  testing::write_rendered_plane_scene(dir_, testing::PlaneCamera{}, poses);
  const FrontendResult r = run_frontend(dir_, options());
  EXPECT_GT(r.summary.keypoints_per_image, 300);
  EXPECT_GE(r.summary.pairs_verified, 5u);
  ASSERT_GT(r.summary.points, 100u);
  // Keypoints at whole pixels of the network's input: well under two pixels.
  EXPECT_LT(r.summary.mean_error_px, 1.5);
  // XFeat's keypoints are whole pixels of its input: half a pixel over the widest baseline (1.2 m, 300 px
  // focal) is 3.5 cm of depth at 5 m. Median within 1.5 cm, under 5 % beyond 15 cm (wrong matches).
  std::vector<double> off;
  for (const auto& p : r.data.points) {
    ASSERT_TRUE(p.xyz.allFinite());
    off.push_back(std::abs(p.xyz.z() - testing::kPlaneZ));
  }
  std::sort(off.begin(), off.end());
  const size_t far = size_t(off.end() - std::upper_bound(off.begin(), off.end(), 0.15));
  EXPECT_LT(off[off.size() / 2], 0.015);
  EXPECT_LT(far, off.size() / 20);
  std::printf("xfeat over a plane: %zu points, median %.4f m off the plane, %zu beyond 0.15 m\n", off.size(),
              off[off.size() / 2], far);
  for (const auto& image : r.data.images)
    for (const auto& k : image.keypoints) {
      ASSERT_GE(k.x, -0.5f);
      ASSERT_LT(k.x, 319.5f);
      ASSERT_GE(k.y, -0.5f);
      ASSERT_LT(k.y, 239.5f);
    }
}

// `--xfeat-scale 2`: the network runs on the frames enlarged twice (640x480), its keypoints come back in the
// frames' pixels and lie on half pixels of them: the tracks agree with their points more closely than at
// the frames' own size, and the points lie on the plane within the same bounds. A scale that leaves less
// than 32x32, or one out of range, is refused by name.
TEST_F(FrontendXfeat, TwiceTheInputGivesFinerKeypointsInTheFrame) {
  std::vector<Eigen::Isometry3d> poses;
  for (int i = 0; i < 4; ++i) poses.push_back(testing::plane_view({0.4 * i, 0.05 * i, 0}));
  testing::write_rendered_plane_scene(dir_, testing::PlaneCamera{}, poses);
  const auto median_off_plane = [](const FrontendResult& r) {
    std::vector<double> off;
    for (const auto& p : r.data.points) off.push_back(std::abs(p.xyz.z() - testing::kPlaneZ));
    std::sort(off.begin(), off.end());
    return off.empty() ? 1e9 : off[off.size() / 2];
  };
  const FrontendResult once = run_frontend(dir_, options());
  FrontendOptions o = options();
  o.features.xfeat_scale = 2;
  o = nn::with_learned_detector(o);
  const FrontendResult twice = run_frontend(dir_, o);
  ASSERT_GT(twice.summary.points, 100u);
  EXPECT_LT(twice.summary.mean_error_px, 1.5);
  const bool off_half_pixel = [&] {
    for (const auto& image : twice.data.images)
      for (const auto& k : image.keypoints) {
        EXPECT_GE(k.x, -0.5f);
        EXPECT_LT(k.x, 319.5f);
        EXPECT_GE(k.y, -0.5f);
        EXPECT_LT(k.y, 239.5f);
        if (std::abs(k.x - std::round(k.x)) > 0.1f) return true;
      }
    return false;
  }();
  EXPECT_TRUE(off_half_pixel) << "every keypoint on a whole pixel of the frame: the input was not enlarged";
  EXPECT_LT(twice.summary.mean_error_px, once.summary.mean_error_px);
  EXPECT_LT(median_off_plane(twice), 0.015);
  std::printf("xfeat over a plane, input x1 / x2: median %.4f / %.4f m off the plane, %.3f / %.3f px\n",
              median_off_plane(once), median_off_plane(twice), once.summary.mean_error_px,
              twice.summary.mean_error_px);

  FrontendOptions small = options();
  small.features.xfeat_scale = 0.5;
  small = nn::with_learned_detector(small);
  try {
    small.learned_detector(Gray8{40, 40, std::vector<uint8_t>(40 * 40, 1)});
    ADD_FAILURE() << "a 40x40 frame at half size was detected on";
  } catch (const std::invalid_argument& e) {
    EXPECT_NE(std::string(e.what()).find("xfeat_scale"), std::string::npos) << e.what();
  }
  FeatureOptions too_large;
  too_large.xfeat_scale = 5;
  EXPECT_THROW(too_large.check(), std::invalid_argument);
}

// LighterGlue on the device as the matcher (`--matcher lighterglue`): the same plane, the same bounds as the
// mnn matcher's above; a bit-string descriptor is refused with a message naming xfeat.
TEST_F(FrontendXfeat, LighterGlueMatchesTheTranslationOverAPlane) {
  std::vector<Eigen::Isometry3d> poses;
  for (int i = 0; i < 4; ++i) poses.push_back(testing::plane_view({0.4 * i, 0.05 * i, 0}));
  testing::write_rendered_plane_scene(dir_, testing::PlaneCamera{}, poses);
  FrontendOptions o = options();
  o.features.max_keypoints = 600;  // attention is quadratic in the keypoints: lavapipe's time
  o.match.matcher = Matcher::kLighterGlue;
  o = nn::with_learned_detector(o);
  const FrontendResult r = run_frontend(dir_, o);
  EXPECT_GE(r.summary.pairs_verified, 5u);
  ASSERT_GT(r.summary.points, 100u);
  EXPECT_LT(r.summary.mean_error_px, 1.5);
  std::vector<double> off;
  for (const auto& p : r.data.points) off.push_back(std::abs(p.xyz.z() - testing::kPlaneZ));
  std::sort(off.begin(), off.end());
  const size_t far = size_t(off.end() - std::upper_bound(off.begin(), off.end(), 0.15));
  EXPECT_LT(off[off.size() / 2], 0.015);
  EXPECT_LT(far, off.size() / 20);
  std::printf("lighterglue over a plane: %zu points, inlier ratio %.3f, median %.4f m off the plane\n",
              off.size(), r.summary.inlier_ratio, off[off.size() / 2]);

  ImageFeatures bits;
  bits.keypoints = {{10, 10, 4, 0}};
  bits.descriptors.assign(32, 0);
  bits.descriptor_bytes = 32;
  try {
    o.learned_matcher(bits, bits, 320, 240);
    ADD_FAILURE() << "bit strings were matched by lighterglue";
  } catch (const std::invalid_argument& e) {
    EXPECT_NE(std::string(e.what()).find("xfeat"), std::string::npos) << e.what();
  }
}

TEST_F(FrontendXfeat, AUniformFrameGivesNoKeypointsAndMissingPiecesAreClearErrors) {
  const FrontendOptions o = options();
  Gray8 uniform{64, 64, std::vector<uint8_t>(64 * 64, 90)};
  const ImageFeatures f = o.learned_detector(uniform);
  EXPECT_TRUE(f.keypoints.empty());
  EXPECT_TRUE(f.float_descriptors);
  EXPECT_THROW(o.learned_detector(Gray8{16, 40, std::vector<uint8_t>(16 * 40, 1)}), std::invalid_argument);
  FrontendOptions without = o;
  without.learned_detector = nullptr;
  EXPECT_THROW(without.check(), std::invalid_argument);
  FeatureOptions xfeat;
  xfeat.type = FeatureType::kXfeat;
  EXPECT_THROW(detect_features(uniform, xfeat), std::invalid_argument);
  ImageFeatures bits;
  bits.keypoints.resize(1);
  bits.descriptor_bytes = 32;
  bits.descriptors.resize(32);
  MatchOptions mnn;
  mnn.matcher = Matcher::kMnn;
  EXPECT_THROW(match_mutual(bits, bits, mnn), std::invalid_argument);
}

}  // namespace
}  // namespace litgs::host::frontend
