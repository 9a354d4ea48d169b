#include "host/synth/calibration_set.h"

#include <optional>
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

// The scene preset made through M2DGR's calibration file (--rig), whose camera and extrinsics a board set
// takes; none without --rig.
std::optional<Preset> rig_preset(const SynthOptions& o) {
  if (o.rig.empty()) return std::nullopt;
  Preset p = make_preset(preset_names().front(), o.seed, Appearance::kTextured);
  apply_m2dgr_rig({o.rig, o.rig_camera_block, o.rig_imu_block}, o.width, o.height, p);
  return p;
}

// `camera` as the rig's thermal camera, or a default pinhole of --width x --height (320x256 unless given),
// with the scene presets' optics blur and the sensor's noise times --sensor-noise.
ThermalCameraOptions board_camera(const SynthOptions& o, ThermalCameraOptions camera,
                                  const std::optional<Preset>& rig) {
  if (rig) {
    camera.calibrated = rig->camera.calibrated;
    camera.width = rig->camera.width;
    camera.height = rig->camera.height;
  } else {
    camera.width = o.width.value_or(320);
    camera.height = o.height.value_or(256);
  }
  camera.blur_px = 0.5;  // the optics' blur of the scene presets' textured appearance
  camera.temporal_noise_raw *= o.sensor_noise;
  camera.fixed_pattern_raw *= o.sensor_noise;
  return camera;
}

}  // namespace

CalibrationSetReport generate_calibration_set(const SynthOptions& o, bool hot_circles) {
  if (o.preset != kCircleGridPreset)
    throw std::invalid_argument("synth: generate_calibration_set needs preset circle-grid, got " + o.preset);
  check_shared_options(o);

  CircleGridViewOptions c;
  const std::optional<Preset> rig = rig_preset(o);
  c.camera = board_camera(o, c.camera, rig);
  if (rig) {
    // The board held nearer a wider lens, so that it fills about as much of the image as with the default.
    ThermalCameraOptions reference;
    reference.width = c.camera.width;
    reference.height = c.camera.height;
    const double nearer = c.camera.calibrated->fx / reference.intrinsics().fx;
    c.min_distance_m *= nearer;
    c.max_distance_m *= nearer;
  }
  if (o.range_noise_m)
    throw std::invalid_argument("synth: --range-noise applies to --preset holed-board only");
  c.views = o.frames.value_or(40);
  c.seed = o.seed;
  c.hot_circles = hot_circles;
  if (const std::string problem = c.check(); !problem.empty())
    throw std::invalid_argument("synth: circle grid: " + problem);
  prepare_synth_output(o.out, o.force, {"images", "truth.json"}, "images/ and truth.json");
  write_circle_grid_set(o.out, c, resolve_synth_threads(o.threads));
  return {c.views, c.grid, c.camera.intrinsics().width, c.camera.intrinsics().height, rig.has_value()};
}

HoledBoardSetReport generate_holed_board_set(const SynthOptions& o) {
  if (o.preset != kHoledBoardPreset)
    throw std::invalid_argument("synth: generate_holed_board_set needs preset holed-board, got " + o.preset);
  check_shared_options(o);
  HoledBoardViewOptions h;
  const std::optional<Preset> rig = rig_preset(o);
  h.camera = board_camera(o, h.camera, rig);
  if (rig) h.T_lidar_cam = rig->T_imu_lidar.inverse() * rig->T_imu_cam;
  if (o.range_noise_m) h.lidar.range_noise_m = *o.range_noise_m;
  h.views = o.frames.value_or(40);
  h.seed = o.seed;
  if (const std::string problem = h.check(); !problem.empty())
    throw std::invalid_argument("synth: holed board: " + problem);
  prepare_synth_output(o.out, o.force, {"images", "scans", "board.yaml", "camera.yaml", "truth.json"},
                       "images/, scans/, board.yaml, camera.yaml and truth.json");
  write_holed_board_set(o.out, h, resolve_synth_threads(o.threads));
  return {h.views, h.camera.intrinsics().width, h.camera.intrinsics().height, rig.has_value()};
}

}  // namespace litgs::host::synth
