#include "host/run/stage_estimate.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <memory>
#include <nlohmann/json.hpp>
#include <thread>

#include "host/refine/scan_alignment.h"
#include "host/train/train_defaults.h"
#include "io/scene_yaml.h"

namespace litgs::host::run {
namespace {

namespace fs = std::filesystem;

// The cost models' coefficients. Seconds per megapixel-frame (frames x width x height / 1e6) unless named
// otherwise; fitted to the stages' times of `run` on the demo, the synthetic facade at 320x256 and DUNR on
// the 2-core development machine (docs/results.md, "What a run will cost", lists estimate against time).
constexpr double kSynthSecondsPerMpx = 1.4;    // rendering frames, scans and the maps
constexpr double kImportSecondsPerMpx = 0.05;  // reading and converting recorded frames
constexpr double kEvalSecondsPerMpx = 0.05;    // rendering and scoring the held-out views
constexpr double kMapSecondsPerScanMb = 0.026;
constexpr double kMatchSecondsPerMpx = 0.8;  // on 2 threads
// XFeat (match.features xfeat): its network on the device, per megapixel of the network's input (the
// frames times match.xfeat_scale squared; DUNR's 45 frames at 640x512 on lavapipe: 12, 57 and 92 s of
// features at scales 1, 2 and 3), and matching and tracks over its 3,000 keypoints per frame with more
// conflicts.
constexpr double kXfeatCpuDeviceSecondsPerMpx = 0.85;
constexpr double kXfeatMatchSecondsPerMpx = 2.3;
// Refine on 2 threads, with the LiDAR point-to-plane term: fitted to `ci/refine-bench`'s refinements
// (facade, street and corridor at 320x256) with and without the scans, whose term is per scan for each
// round it is in the solve (refine.scans: the map the poses build, and its residuals). Without the LiDAR:
// DUNR's refinement in `run`.
constexpr double kRefineSecondsPerMpxLidar = 6.8;
constexpr double kRefineSecondsPerScanRound = 0.015;
constexpr double kRefineSecondsPerMpxNoLidar = 1.34;
// Training on a CPU device (lavapipe, 2 cores): per iteration (a + b per thousand Gaussians) at 320x256,
// scaled by (pixels / 320x256)^0.85 (4x the pixels: 3.2-3.4x the time up to 100k Gaussians).
constexpr double kCpuMsPerIteration = 30.7, kCpuMsPerThousandGaussians = 1.13, kCpuPixelExponent = 0.85;
// On a GPU: one H200's DUNR training and `bench render` (1.3-2.2 ms per iteration; slower GPUs take longer).
constexpr double kGpuMsPerIteration = 2.0, kGpuMsPerMillionGaussians = 2.5, kGpuPixelExponent = 0.3;
constexpr double kTrainStartSeconds = 3.0;  // loading frames, the initialization, the final evaluation
// Two threads take 0.58-0.64 of one thread's time on these stages: time scales as threads^-0.7.
constexpr double kThreadExponent = 0.7;
// grow's high end: four doublings, as many as its decisions' window held on the synthetic facade.
constexpr uint32_t kGrowDoublingsAssumed = 4;

double megapixel_frames(const RunSize& s) {
  return static_cast<double>(s.frames) * s.width * s.height / 1e6;
}

double thread_factor(double threads) {
  return std::pow(2.0 / std::max(threads, 1.0), kThreadExponent);
}

std::string thousands(double n) {
  char buf[32];
  if (n >= 1e6)
    std::snprintf(buf, sizeof buf, "%.3gM", n / 1e6);
  else
    std::snprintf(buf, sizeof buf, "%.0fk", n / 1e3);
  return buf;
}

std::string size_text(const RunSize& s) {
  return std::to_string(s.frames) + " frames at " + std::to_string(s.width) + "x" + std::to_string(s.height);
}

StageEstimate fixed(double seconds, std::string basis) {
  return {seconds, seconds, std::move(basis)};
}

double train_seconds(const RunSize& s, const RunConfig::Train& t, const EstimateDevice& d, double gaussians) {
  const double ds = std::max(t.downscale, 1e-9);
  const double pixels = (s.width / ds) * (s.height / ds);
  double ms;
  if (d.cpu)
    ms = (kCpuMsPerIteration + kCpuMsPerThousandGaussians * gaussians / 1e3) *
         std::pow(pixels / (320.0 * 256.0), kCpuPixelExponent) * thread_factor(d.host_cores);
  else
    ms = (kGpuMsPerIteration + kGpuMsPerMillionGaussians * gaussians / 1e6) *
         std::pow(std::max(pixels / (320.0 * 256.0), 1.0), kGpuPixelExponent);
  return kTrainStartSeconds + t.iterations * ms / 1e3;
}

std::optional<StageEstimate> estimate_train(const RunSize& s, const RunConfig::Train& t,
                                            const EstimateDevice& d, std::string& why) {
  if (d.name.empty()) {
    why = "no Vulkan device answered `litgs-engine info`";
    return std::nullopt;
  }
  if (t.blocks != "1") {
    why =
        "trained in blocks (train.blocks " + t.blocks + "): the blocks' views are known after the partition";
    return std::nullopt;
  }
  double low = 0, high = 0;
  if (t.max_gaussians == "grow") {
    low = train_defaults::kGrowthStart;
    high = low * std::pow(2.0, kGrowDoublingsAssumed);
  } else if (t.max_gaussians == "search" || t.max_gaussians == "auto") {
    why = "the budget " + t.max_gaussians + " decides how much is trained";
    return std::nullopt;
  } else if (t.strategy != "mcmc") {
    why = "adc: the count the densification reaches decides";
    return std::nullopt;
  } else {
    try {
      low = high = std::stod(t.max_gaussians);
    } catch (const std::exception&) {
      why = "budget '" + t.max_gaussians + "' is not a count";
      return std::nullopt;
    }
  }
  const double ds = std::max(t.downscale, 1e-9);
  const std::string pixels =
      std::to_string(static_cast<int>(s.width / ds)) + "x" + std::to_string(static_cast<int>(s.height / ds));
  const std::string budget = low == high ? thousands(low) : thousands(low) + "-" + thousands(high);
  return StageEstimate{
      train_seconds(s, t, d, low), train_seconds(s, t, d, high),
      std::to_string(t.iterations) + " iterations at " + pixels + ", " + budget + " Gaussians, on " + d.name};
}

}  // namespace

std::optional<RunSize> size_before_import(InputKind kind, const fs::path& input, const RunConfig& config) {
  if (kind == InputKind::kScene) return size_of_scene(input);
  if (kind != InputKind::kSynthetic) return std::nullopt;
  RunSize s;
  s.frames = config.import.synth_frames;
  s.width = config.import.synth_width;
  s.height = config.import.synth_height;
  s.lidar_map = s.map_file = true;  // synth writes its map
  s.scans = s.frames;               // and one scan per frame
  return s;
}

RunSize size_of_scene(const fs::path& dir) {
  RunSize s;
  const io::SceneConfig c = io::read_scene_yaml(dir / "scene.yaml");
  s.width = static_cast<uint32_t>(c.camera.width);
  s.height = static_cast<uint32_t>(c.camera.height);
  s.lidar_map = s.map_file = c.has_lidar_map && fs::is_regular_file(dir / "lidar" / "map.pcd");
  std::error_code ec;
  for (const auto& e : fs::directory_iterator(dir / "thermal", ec))
    if (e.is_regular_file()) ++s.frames;
  for (const auto& e : fs::directory_iterator(dir / "lidar" / "scans", ec))
    if (e.is_regular_file()) {
      ++s.scans;
      s.scan_bytes += e.file_size(ec);
      s.lidar_map = true;  // map builds one from them
    }
  return s;
}

EstimateDevice query_device(const fs::path& engine) {
  EstimateDevice d;
  d.host_cores = std::max(1u, std::thread::hardware_concurrency());
  const std::string command = "'" + engine.string() + "' info --json 2>/dev/null";
  std::unique_ptr<FILE, int (*)(FILE*)> pipe(popen(command.c_str(), "r"), pclose);
  if (!pipe) return d;
  std::string text;
  char buf[4096];
  for (size_t n; (n = fread(buf, 1, sizeof buf, pipe.get())) > 0;) text.append(buf, n);
  const nlohmann::json j = nlohmann::json::parse(text, nullptr, false);
  if (!j.is_object() || !j.value("name", nlohmann::json()).is_string()) return d;
  d.name = j["name"].get<std::string>();
  d.cpu = j.value("type", std::string("cpu")) == "cpu";
  return d;
}

std::optional<StageEstimate> estimate_stage(const std::string& stage, InputKind kind, const RunSize& s,
                                            const RunConfig& c, const EstimateDevice& d, std::string* why) {
  std::string reason;
  std::optional<StageEstimate> e;
  const double mpx = megapixel_frames(s);
  const unsigned cores = std::max(1u, d.host_cores);
  if (stage == "import") {
    if (kind == InputKind::kScene)
      e = fixed(0, "a scene directory, used in place");
    else if (kind == InputKind::kSynthetic)
      e = fixed(0.5 + kSynthSecondsPerMpx * mpx, "rendering " + size_text(s));
    else
      e = fixed(0.5 + kImportSecondsPerMpx * mpx, "reading " + size_text(s));
  } else if (stage == "map") {
    if (c.map.build == "never" || (c.map.build == "auto" && (s.scans == 0 || s.map_file)))
      e = fixed(0, "no map to build");
    else
      e = fixed(0.5 + kMapSecondsPerScanMb * static_cast<double>(s.scan_bytes) / 1e6,
                std::to_string(s.scans) + " scans");
  } else if (stage == "match" && !c.match.enabled) {
    e = fixed(0, "match.enabled is false");
  } else if (stage == "refine" && !c.refine.enabled) {
    e = fixed(0, "refine.enabled is false");
  } else if (stage == "match" && c.match.matcher == "lighterglue") {
    // Each pair costs the square of its keypoints, and the pairs are known after pair selection.
    reason =
        "LighterGlue's time grows with the pairs and the square of the keypoints per frame (`bench "
        "features` times one pair)";
  } else if (stage == "match") {
    const double threads = c.match.threads ? c.match.threads : cores;
    if (c.match.features == "xfeat")
      e = fixed(
          1.0 + ((d.cpu ? kXfeatCpuDeviceSecondsPerMpx * c.match.xfeat_scale * c.match.xfeat_scale : 0.0) +
                 kXfeatMatchSecondsPerMpx) *
                    mpx * thread_factor(threads),
          size_text(s) + ", XFeat on " + (d.name.empty() ? std::string("the device") : d.name));
    else
      e = fixed(1.0 + kMatchSecondsPerMpx * mpx * thread_factor(threads),
                size_text(s) + " on " + std::to_string(static_cast<int>(threads)) + " threads");
  } else if (stage == "refine") {
    const bool planes = s.lidar_map && c.refine.planes;
    const size_t from_round = refine::ScanAlignmentOptions{}.from_round;
    const size_t scan_rounds =
        c.refine.scans && c.refine.rounds > from_round ? c.refine.rounds - from_round : 0;
    const double scans = kRefineSecondsPerScanRound * s.scans * static_cast<double>(scan_rounds);
    const double threads = c.refine.threads ? c.refine.threads : cores;
    e = fixed(1.0 + ((planes ? kRefineSecondsPerMpxLidar : kRefineSecondsPerMpxNoLidar) * mpx + scans) *
                        thread_factor(threads),
              size_text(s) + " on " + std::to_string(static_cast<int>(threads)) + " threads" +
                  (planes ? ", with LiDAR planes" : ", without LiDAR planes") +
                  (s.scans && scan_rounds ? ", " + std::to_string(s.scans) + " scans in the last " +
                                                std::to_string(scan_rounds) + " rounds"
                                          : ""));
  } else if (stage == "train") {
    e = estimate_train(s, c.train, d, reason);
  } else if (stage == "eval") {
    const double emd = c.eval.geometry && s.lidar_map
                           ? 0.4 * c.eval.emd_rounds * std::pow(c.eval.emd_samples / 1000.0, 3)
                           : 0.0;
    e = fixed(1.5 + emd + kEvalSecondsPerMpx * mpx, "held-out views of " + size_text(s));
  } else if (stage == "report") {
    e = fixed(0.2, "the report page");
  } else {
    reason = "no cost model for stage '" + stage + "'";
  }
  if (why) *why = reason;
  return e;
}

std::string estimate_text(const StageEstimate& e) {
  const auto one = [](double s, bool unit) {
    char buf[32];
    if (s < 90)
      std::snprintf(buf, sizeof buf, unit ? "%.0f s" : "%.0f", std::max(s, 1.0));
    else if (s < 5400)
      std::snprintf(buf, sizeof buf, unit ? "%.0f min" : "%.0f", s / 60);
    else
      std::snprintf(buf, sizeof buf, unit ? "%.1f h" : "%.1f", s / 3600);
    return std::string(buf);
  };
  const auto unit_of = [](double s) { return s < 90 ? 0 : s < 5400 ? 1 : 2; };
  if (e.high_s <= e.low_s * 1.1) return "about " + one(e.low_s, true);
  if (unit_of(e.low_s) == unit_of(e.high_s))
    return "about " + one(e.low_s, false) + "-" + one(e.high_s, true);
  return "about " + one(e.low_s, true) + " to " + one(e.high_s, true);
}

}  // namespace litgs::host::run
