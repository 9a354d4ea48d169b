// What each stage of `litgs-engine run` will cost, said before it starts: seconds from the scene's size
// (frames, pixels), the run's options (iterations, budget, threads) and the device's kind. An estimate,
// labelled as one: each stage's cost model is a few terms fitted to stage times measured on a 2-core machine
// with lavapipe, and for a GPU to one H200 (docs/results.md, "What a run will cost"); run.json keeps the
// estimate beside the time taken, so that its error is measured on every run.
#pragma once

#include <cstdint>
#include <filesystem>
#include <optional>
#include <string>

#include "host/run/input_kind.h"
#include "host/run/run_config.h"

namespace litgs::host::run {

// The size the estimates scale with.
struct RunSize {
  uint32_t frames = 0;
  uint32_t width = 0, height = 0;  // of the frames, before train's downscale
  uint32_t scans = 0;              // lidar/scans/ (map builds from them)
  uint64_t scan_bytes = 0;
  bool lidar_map = false;  // the scene has a LiDAR map, or map will build one
  bool map_file = false;   // lidar/map.pcd exists already
};

// The device the training runs on, as `litgs-engine info --json` names it.
struct EstimateDevice {
  std::string name;         // empty: no device answered (the training has no estimate)
  bool cpu = true;          // a CPU device (lavapipe), which shares the host's cores
  unsigned host_cores = 1;  // the host's cores: the CPU stages' threads and a CPU device's
};

// low_s == high_s for a stage whose work the options fix; a range where the run decides (a grown budget).
struct StageEstimate {
  double low_s = 0, high_s = 0;
  std::string basis;  // what it was scaled from, e.g. "2,000 iterations at 320x256, 10k-160k Gaussians"
};

// The size before the import runs: a scene directory's scene.yaml and folders, or synth's options; nullopt
// for inputs whose size only the import finds out (bags, Metashape, COLMAP, FAST-LIVO2).
std::optional<RunSize> size_before_import(InputKind kind, const std::filesystem::path& input,
                                          const RunConfig& config);
// The size of a scene directory (scene.yaml and the folders; frames' pixels are not read).
RunSize size_of_scene(const std::filesystem::path& scene_dir);

// Asks `engine info --json` which device the stages will use; a device-less EstimateDevice when it fails.
EstimateDevice query_device(const std::filesystem::path& engine);

// The stage's estimate; nullopt when there is none (no device for the training, a budget search whose trial
// count the scene decides), with the reason in *why.
std::optional<StageEstimate> estimate_stage(const std::string& stage, InputKind kind, const RunSize& size,
                                            const RunConfig& config, const EstimateDevice& device,
                                            std::string* why = nullptr);

// "about 40 s", "about 2-7 min": rounded as an estimate should be.
std::string estimate_text(const StageEstimate& e);

}  // namespace litgs::host::run
