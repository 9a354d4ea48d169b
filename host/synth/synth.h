// `litgs-engine synth`: a complete synthetic scene directory (docs/scene-format.md) with exact ground truth,
// from a named preset and a seed. The same options give the same bytes.
#pragma once

#include <cstdint>
#include <filesystem>
#include <optional>
#include <string>
#include <vector>

#include "io/scene_types.h"

namespace litgs::host::synth {

struct SynthOptions {
  std::string preset = "facade";  // facade (default) | street | corridor
  uint64_t seed = 1;              // everything random derives from it
  std::optional<int> frames;      // thermal frames (= LiDAR scans); default: the preset's (facade 60)
  // Frames (and scans) per second; default the presets' 10 Hz. A higher rate puts more frames on the same
  // path: the presets' frame limits scale with it.
  std::optional<double> frame_rate_hz;
  std::optional<int> width, height;  // thermal image size, both or neither; default 320 x 256
  std::filesystem::path out;         // the scene directory to write
  bool force = false;                // replace the scene files in a non-empty `out`
  int threads = 0;                   // worker threads; 0: the hardware's (at most 8)
  // A known level drift of the raw counts (host/synth/level_drift.h): a slow warm-up in gain and offset and
  // a jump at the first NUC freeze; the true per-frame gain and offset go to gt/levels.txt.
  bool drift = false;
  // "textured" (the default: weathered surfaces calibrated against real frames) | "flat" (the smooth
  // blocks of earlier versions); presets.h, Appearance.
  std::string appearance = "textured";
  // Scans 0, N, 2N, ... left out of lidar/map.pcd, as `litgs-engine map` does (scene.yaml
  // lidar_holdout_every); 0: every scan in the map. Sequences under 2N frames hold none out.
  int lidar_holdout_every = io::kDefaultLidarHoldoutEvery;
  // A real rig instead of the preset's (host/synth/m2dgr_rig.h): M2DGR's calibration file, the camera block
  // to simulate and the IMU block the body follows. width and height then scale the calibrated camera.
  std::filesystem::path rig;
  std::string rig_camera_block = "Cam-thermal";
  std::string rig_imu_block = "Handsfree IMU";
  // Calibration sets only (circle-grid, holed-board): the thermal camera's temporal and fixed-pattern noise
  // times this; holed-board: the LiDAR's range noise (standard deviation, metres; default 0.01).
  double sensor_noise = 1;
  std::optional<double> range_noise_m;

  // Empty if valid, else the first bad field and why (std::invalid_argument from generate_* carries it).
  std::string check() const;
};

struct SynthReport {
  std::string preset;
  int frames = 0;
  int frozen_frames = 0;   // frames that repeat the previous one (gt/frozen.txt)
  size_t scan_points = 0;  // over all scans
  size_t map_points = 0;   // lidar/map.pcd after voxel downsampling
  size_t anchors = 0;
  size_t imu_samples = 0;
  size_t planes = 0;         // gt/planes.txt
  double path_length_m = 0;  // travelled between the first and the last frame
  double final_drift_m = 0;  // |estimated - true| position of the last frame
  double seconds = 0;        // wall time of the whole generation
};

// Generates and writes the scene. std::invalid_argument (naming the field) on bad options or a non-empty
// `out` without `force`; io::IoError on file errors. Files are written atomically, scene.yaml last.
SynthReport generate_synthetic_scene(const SynthOptions& options);

// Makes `out` ready for a synthetic output: created if missing; if it is not empty, refused without `force`
// (the message names what --force would replace), else `entries` (files or folders in it) are removed and
// nothing else. std::invalid_argument when it is refused or `out` is a file.
void prepare_synth_output(const std::filesystem::path& out, bool force,
                          const std::vector<std::string>& entries, const std::string& what_force_replaces);

// SynthOptions::threads as a count: 0 gives the hardware's, at most 8.
int resolve_synth_threads(int requested);

}  // namespace litgs::host::synth
