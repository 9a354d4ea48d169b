#include "host/synth/calibration_set.h"

#include <stdexcept>

#include "host/synth/m2dgr_rig.h"
#include "host/synth/presets.h"

namespace litgs::host::synth {
namespace {

// The scene options a board seen from still poses has no use for: refused rather than ignored.
void refuse_scene_options(const SynthOptions& o) {
  const SynthOptions defaults;
  const auto refuse = [&](const std::string& flag) {
    throw std::invalid_argument("synth: " + flag + " does not apply to --preset " + o.preset +
                                " (a calibration set)");
  };
  if (o.drift) refuse("--drift");
  if (o.frame_rate_hz) refuse("--frame-rate");
  if (o.appearance != defaults.appearance) refuse("--appearance");
  if (o.lidar_holdout_every != defaults.lidar_holdout_every) refuse("--lidar-holdout-every");
}

// The checks shared with the scene presets, asked of a scene preset so that only the preset's name differs.
void check_shared_options(const SynthOptions& o) {
  refuse_scene_options(o);
  SynthOptions shared = o;
  shared.preset = preset_names().front();
  if (const std::string problem = shared.check(); !problem.empty())
    throw std::invalid_argument("synth: " + problem);
}

}  // namespace

CalibrationSetReport generate_calibration_set(const SynthOptions& o, bool hot_circles) {
  if (o.preset != kCircleGridPreset)
    throw std::invalid_argument("synth: generate_calibration_set needs preset circle-grid, got " + o.preset);
  check_shared_options(o);

  CircleGridViewOptions c;
  if (!o.rig.empty()) {
    Preset p = make_preset(preset_names().front(), o.seed, Appearance::kTextured);
    apply_m2dgr_rig({o.rig, o.rig_camera_block, o.rig_imu_block}, o.width, o.height, p);
    // The board held nearer a wider lens, so that it fills about as much of the image as with the default.
    ThermalCameraOptions reference;
    reference.width = p.camera.width;
    reference.height = p.camera.height;
    const double nearer = p.camera.calibrated->fx / reference.intrinsics().fx;
    c.min_distance_m *= nearer;
    c.max_distance_m *= nearer;
    c.camera.calibrated = p.camera.calibrated;
    c.camera.width = p.camera.width;
    c.camera.height = p.camera.height;
  } else {
    c.camera.width = o.width.value_or(320);
    c.camera.height = o.height.value_or(256);
  }
  if (o.range_noise_m)
    throw std::invalid_argument("synth: --range-noise applies to --preset holed-board only");
  c.camera.blur_px = 0.5;  // the optics' blur of the scene presets' textured appearance
  c.camera.temporal_noise_raw *= o.sensor_noise;
  c.camera.fixed_pattern_raw *= o.sensor_noise;
  c.views = o.frames.value_or(40);
  c.seed = o.seed;
  c.hot_circles = hot_circles;
  if (const std::string problem = c.check(); !problem.empty())
    throw std::invalid_argument("synth: circle grid: " + problem);
  prepare_synth_output(o.out, o.force, {"images", "truth.json"}, "images/ and truth.json");
  write_circle_grid_set(o.out, c, resolve_synth_threads(o.threads));
  return {c.views, c.grid, c.camera.intrinsics().width, c.camera.intrinsics().height, !o.rig.empty()};
}

HoledBoardSetReport generate_holed_board_set(const SynthOptions& o) {
  if (o.preset != kHoledBoardPreset)
    throw std::invalid_argument("synth: generate_holed_board_set needs preset holed-board, got " + o.preset);
  check_shared_options(o);
  HoledBoardViewOptions h;
  if (!o.rig.empty()) {
    Preset p = make_preset(preset_names().front(), o.seed, Appearance::kTextured);
    apply_m2dgr_rig({o.rig, o.rig_camera_block, o.rig_imu_block}, o.width, o.height, p);
    h.camera.calibrated = p.camera.calibrated;
    h.camera.width = p.camera.width;
    h.camera.height = p.camera.height;
    h.T_lidar_cam = p.T_imu_lidar.inverse() * p.T_imu_cam;
  } else {
    h.camera.width = o.width.value_or(320);
    h.camera.height = o.height.value_or(256);
  }
  h.camera.blur_px = 0.5;  // the optics' blur of the scene presets' textured appearance
  h.camera.temporal_noise_raw *= o.sensor_noise;
  h.camera.fixed_pattern_raw *= o.sensor_noise;
  if (o.range_noise_m) h.lidar.range_noise_m = *o.range_noise_m;
  h.views = o.frames.value_or(40);
  h.seed = o.seed;
  if (const std::string problem = h.check(); !problem.empty())
    throw std::invalid_argument("synth: holed board: " + problem);
  prepare_synth_output(o.out, o.force, {"images", "scans", "board.yaml", "camera.yaml", "truth.json"},
                       "images/, scans/, board.yaml, camera.yaml and truth.json");
  write_holed_board_set(o.out, h, resolve_synth_threads(o.threads));
  return {h.views, h.camera.intrinsics().width, h.camera.intrinsics().height, !o.rig.empty()};
}

}  // namespace litgs::host::synth
