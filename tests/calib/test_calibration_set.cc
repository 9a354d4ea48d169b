// synth --preset circle-grid's policy (host/synth/calibration_set.h): what it refuses, what --force replaces,
// and a set rendered through M2DGR's thermal lens whose distortion calib recovers (the truth calib never
// reads: the rig file).
#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>
#include <nlohmann/json.hpp>

#include "calib/circle_grid.h"
#include "calib/intrinsics.h"
#include "host/synth/calibration_set.h"
#include "io/image.h"

namespace litgs::host::synth {
namespace {

namespace fs = std::filesystem;

fs::path fresh_dir(const std::string& name) {
  const fs::path d = fs::temp_directory_path() / ("litgs-calibration-set-" + name);
  fs::remove_all(d);
  return d;
}

SynthOptions circle_grid_options(const fs::path& out, int views) {
  SynthOptions o;
  o.preset = kCircleGridPreset;
  o.out = out;
  o.frames = views;
  o.threads = 2;
  return o;
}

void expect_refused(const SynthOptions& o, const std::string& words) {
  try {
    generate_calibration_set(o, true);
    FAIL() << "accepted; expected a refusal naming " << words;
  } catch (const std::invalid_argument& e) {
    EXPECT_NE(std::string(e.what()).find(words), std::string::npos) << e.what();
  }
}

TEST(CalibrationSet, SceneOptionsThatDoNotApplyAreRefusedNotIgnored) {
  const fs::path out = fresh_dir("refused");
  SynthOptions o = circle_grid_options(out, 3);
  o.drift = true;
  expect_refused(o, "--drift does not apply to --preset circle-grid");
  o = circle_grid_options(out, 3);
  o.frame_rate_hz = 30;
  expect_refused(o, "--frame-rate does not apply");
  o = circle_grid_options(out, 3);
  o.appearance = "flat";
  expect_refused(o, "--appearance does not apply");
  o = circle_grid_options(out, 3);
  o.lidar_holdout_every = 0;
  expect_refused(o, "--lidar-holdout-every does not apply");
  o = circle_grid_options(out, 3);
  o.width = 320;
  expect_refused(o, "width/height: give both or neither");
  EXPECT_FALSE(fs::exists(out)) << "nothing is written before the options are known to be good";
}

TEST(CalibrationSet, ANonEmptyOutIsRefusedWithoutForceAndItsOtherFilesSurviveForce) {
  const fs::path out = fresh_dir("force");
  fs::create_directories(out);
  std::ofstream(out / "notes.txt") << "mine\n";
  SynthOptions o = circle_grid_options(out, 2);
  expect_refused(o, "exists and is not empty (use --force");
  EXPECT_FALSE(fs::exists(out / "images"));
  o.force = true;
  const CalibrationSetReport r = generate_calibration_set(o, true);
  EXPECT_EQ(r.views, 2);
  EXPECT_TRUE(fs::exists(out / "truth.json"));
  EXPECT_TRUE(fs::exists(out / "images" / "view_001.png"));
  EXPECT_TRUE(fs::exists(out / "notes.txt")) << "--force replaces images/ and truth.json only";
  fs::remove_all(out);
}

TEST(CalibrationSet, RenderedThroughTheM2dgrLensCalibRecoversItsDistortion) {
  const fs::path out = fresh_dir("rig");
  SynthOptions o = circle_grid_options(out, 30);
  o.rig = fs::path(LITGS_TEST_DATA_DIR) / "m2dgr/calibration_results.txt";
  o.width = 320;
  o.height = 256;
  const CalibrationSetReport r = generate_calibration_set(o, true);
  EXPECT_TRUE(r.distorted);
  std::ifstream truth_file(out / "truth.json");
  const nlohmann::json truth = nlohmann::json::parse(truth_file)["camera"];
  const std::vector<double> true_distortion = truth["distortion"];
  ASSERT_GE(true_distortion.size(), 2u);
  ASSERT_LT(true_distortion[0], -0.3) << "M2DGR's thermal lens has a strong barrel distortion";

  const calib::CircleGrid grid = calib::parse_circle_grid("4x11", 0.05);
  std::vector<calib::CalibrationView> views;
  for (int i = 0; i < r.views; ++i) {
    char name[32];
    std::snprintf(name, sizeof name, "view_%03d.png", i);
    const io::Image image = io::read_image(out / "images" / name);
    views.push_back({name, image.width, image.height,
                     calib::detect_circle_grid(image, grid, calib::Polarity::kAuto, false)});
  }
  size_t found = 0;
  for (const auto& v : views) found += v.detection.found;
  const calib::IntrinsicsResult c = calib::calibrate_intrinsics(views, grid, {});
  std::printf(
      "  %zu found, %zu of %d views used; fx %.3f (true %.3f), cx %.3f (%.3f), cy %.3f (%.3f), k1 %.4f "
      "(%.4f), "
      "k2 %.4f (%.4f), RMS %.3f px\n",
      found, c.views_used, r.views, c.camera.fx, truth["fx"].get<double>(), c.camera.cx,
      truth["cx"].get<double>(), c.camera.cy, truth["cy"].get<double>(), c.camera.distortion.at(0),
      true_distortion[0], c.camera.distortion.at(1), true_distortion[1], c.rms_px);
  EXPECT_GE(c.views_used, 25u);
  EXPECT_LT(std::abs(c.camera.fx / truth["fx"].get<double>() - 1), 0.005);
  EXPECT_LT(std::hypot(c.camera.cx - truth["cx"].get<double>(), c.camera.cy - truth["cy"].get<double>()),
            1.5);
  EXPECT_NEAR(c.camera.distortion[0], true_distortion[0], 0.05);
  fs::remove_all(out);
}

}  // namespace
}  // namespace litgs::host::synth
