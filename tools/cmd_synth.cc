// `litgs-engine synth --preset NAME --out DIR [--seed S] [--frames N] [--frame-rate HZ] [--width W --height
// H]
// [--force] [--drift]`: a synthetic scene directory with exact ground truth (docs/scene-format.md). CPU only.
#include <CLI/CLI.hpp>
#include <iomanip>
#include <iostream>
#include <memory>

#include "host/synth/calibration_set.h"
#include "host/synth/synth.h"
#include "tools/commands.h"

namespace litgs::tools {

void add_synth_command(CLI::App& app) {
  CLI::App* synth = app.add_subcommand(
      "synth", "Generate a synthetic LiDAR-inertial-thermal scene with exact ground truth");
  auto o = std::make_shared<host::synth::SynthOptions>();
  auto frames = std::make_shared<int>(0);
  auto width = std::make_shared<int>(0);
  auto height = std::make_shared<int>(0);
  synth
      ->add_option("--preset", o->preset,
                   "facade | street | corridor, or circle-grid (a calibration set for `calib intrinsics`) "
                   "or holed-board (one for `calib extrinsic`); --rig renders a set through the rig's lens")
      ->capture_default_str();
  synth->add_option("--out", o->out, "Scene directory to write")->required();
  synth->add_option("--seed", o->seed, "Random seed: the same seed gives the same bytes")
      ->capture_default_str();
  CLI::Option* f =
      synth->add_option("--frames", *frames, "Thermal frames (default: the preset's, facade 60)");
  auto rate = std::make_shared<double>(10);
  CLI::Option* rate_option =
      synth->add_option("--frame-rate", *rate,
                        "Frames (and LiDAR scans) per second (default 10; the presets' frame "
                        "limits and default frame counts scale with it)");
  CLI::Option* w = synth->add_option("--width", *width, "Image width in pixels (default 320)");
  CLI::Option* h = synth->add_option("--height", *height, "Image height in pixels (default 256)");
  synth
      ->add_option("--appearance", o->appearance,
                   "textured (weathered surfaces, blur, column noise: calibrated against real frames) | flat "
                   "(the smooth blocks of earlier versions)")
      ->capture_default_str();
  synth
      ->add_option("--lidar-holdout-every", o->lidar_holdout_every,
                   "Leave scans 0, N, 2N, ... out of lidar/map.pcd, as map does (0: every scan in the map)")
      ->capture_default_str();
  synth
      ->add_option("--rig", o->rig,
                   "M2DGR calibration_results.txt: simulate its thermal camera (intrinsics, distortion, "
                   "extrinsic) and IMU lever arm instead of the preset's rig; --width/--height scale it")
      ->check(CLI::ExistingFile);
  synth->add_option("--rig-camera", o->rig_camera_block, "The --rig block of the camera")
      ->capture_default_str();
  synth->add_option("--rig-imu", o->rig_imu_block, "The --rig block of the IMU (the body frame)")
      ->capture_default_str();
  synth->add_flag("--force", o->force, "Replace the scene files in a non-empty --out");
  synth->add_flag("--drift", o->drift,
                  "A known sensor level drift (slow gain and offset warm-up, an offset jump at the first NUC "
                  "freeze) in the raw frames; the truth in gt/levels.txt");
  synth->add_option("--threads", o->threads, "Worker threads (0: all cores, at most 8)")
      ->capture_default_str();
  synth
      ->add_option(
          "--sensor-noise", o->sensor_noise,
          "circle-grid, holed-board: the thermal camera's temporal and fixed-pattern noise times this")
      ->capture_default_str();
  auto range_noise = std::make_shared<double>(0.01);
  CLI::Option* range_noise_option =
      synth->add_option("--range-noise", *range_noise,
                        "holed-board: the LiDAR's range noise, metres (standard deviation; default 0.01)");
  auto polarity = std::make_shared<std::string>("hot");
  synth
      ->add_option("--polarity", *polarity,
                   "circle-grid: circles hotter (hot) or colder (cold) than the board")
      ->check(CLI::IsMember({"hot", "cold"}))
      ->capture_default_str();
  synth->callback(
      [o, frames, width, height, rate, f, w, h, rate_option, polarity, range_noise, range_noise_option] {
        if (f->count()) o->frames = *frames;
        if (range_noise_option->count()) o->range_noise_m = *range_noise;
        if (rate_option->count()) o->frame_rate_hz = *rate;
        if (w->count()) o->width = *width;
        if (h->count()) o->height = *height;
        if (o->preset == host::synth::kCircleGridPreset) {
          const host::synth::CalibrationSetReport r =
              host::synth::generate_calibration_set(*o, *polarity == "hot");
          std::cout << "synth circle-grid: " << r.views << " views of a " << r.grid.cols << "x" << r.grid.rows
                    << " asymmetric circle grid (" << *polarity << " circles, spacing " << r.grid.spacing_m
                    << " m) at " << r.width << "x" << r.height << (r.distorted ? " through --rig's lens" : "")
                    << "; written to " << o->out.string() << "/images, the truth to truth.json\n";
          return;
        }
        if (o->preset == host::synth::kHoledBoardPreset) {
          const host::synth::HoledBoardSetReport r = host::synth::generate_holed_board_set(*o);
          std::cout << "synth holed-board: " << r.views << " views of a board with 4 holes by the camera at "
                    << r.width << "x" << r.height << " and a 32-ring LiDAR"
                    << (r.rig ? " (--rig's camera and extrinsic)" : "") << "; written to " << o->out.string()
                    << " (images/, scans/, board.yaml, camera.yaml), the truth "
                    << "to truth.json\n";
          return;
        }
        const host::synth::SynthReport r = host::synth::generate_synthetic_scene(*o);
        std::cout << std::fixed << std::setprecision(2) << "synth " << r.preset << ": " << r.frames
                  << " thermal frames (" << r.frozen_frames << " frozen by NUC), " << r.frames
                  << " LiDAR scans with " << r.scan_points << " points, a map of " << r.map_points
                  << " points on " << r.planes << " true planes, " << r.anchors << " anchors, "
                  << r.imu_samples << " IMU samples; path " << r.path_length_m << " m, final pose drift "
                  << r.final_drift_m << " m; written to " << o->out.string() << " in " << r.seconds << " s\n";
      });
}

}  // namespace litgs::tools
