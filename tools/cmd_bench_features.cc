// `litgs-engine bench features [--image FILE] [--runs N] [--json]`: milliseconds per image for each detector
// on one frame, in one run: ORB, SIFT and AKAZE (OpenCV, on the CPU, at the front end's defaults), XFeat's
// network on the Vulkan device (upload, forward pass and download; and the device's time in each of its
// kernels), XFeat as the front end runs it (network, keypoints and descriptors on the device, at match's
// defaults), LighterGlue per pair of frames (and the device's time in each of its kernels) and XFeat's
// double-precision CPU reference of the network (one run). The frame is cropped to multiples of 32.
#include <CLI/CLI.hpp>
#include <algorithm>
#include <cmath>
#include <iomanip>
#include <iostream>
#include <map>
#include <memory>
#include <nlohmann/json.hpp>

#include "engine/context.h"
#include "host/frontend/features.h"
#include "host/frontend/intensity.h"
#include "host/frontend/preprocess.h"
#include "host/nn/embedded_models.h"
#include "host/nn/lighterglue_matcher.h"
#include "host/nn/lighterglue_weights.h"
#include "host/nn/xfeat_features.h"
#include "host/nn/xfeat_weights.h"
#include "io/image.h"
#include "kernels/nn/lighterglue.h"
#include "kernels/nn/xfeat.h"
#include "kernels/nn/xfeat_reference.h"
#include "tools/bench_stats.h"
#include "tools/commands.h"
#include "tools/device_json.h"

namespace litgs::tools {
namespace {

struct BenchFeaturesOptions {
  std::filesystem::path image;  // empty: a 640x512 pattern
  std::filesystem::path model;  // empty: the embedded model
  uint32_t runs = 5;
  bool json = false;
};

// The frame as the front end sees it (a 1-99 percentile stretch to 8 bits), cropped to multiples of 32.
host::frontend::Gray8 load_frame(const std::filesystem::path& path) {
  io::Image raw;
  if (path.empty()) {
    raw.width = 640;
    raw.height = 512;
    raw.data.resize(size_t{640} * 512);
    for (int y = 0; y < raw.height; ++y)
      for (int x = 0; x < raw.width; ++x)
        raw.data[size_t(y) * 640 + x] =
            static_cast<uint16_t>(127 + 60 * std::sin(0.11 * (x + 0.7 * y)) + 40 * std::cos(0.023 * x) +
                                  (((x >> 5) + (y >> 5)) % 2 ? 20 : 0));
  } else {
    raw = io::read_image(path);
  }
  if (raw.channels != 1) throw std::invalid_argument(path.string() + ": a one-channel frame is needed");
  host::frontend::Histogram h = host::frontend::empty_histogram();
  host::frontend::add_to_histogram(h, raw.data);
  const host::frontend::Gray8 full = host::frontend::to_gray8(
      raw, host::frontend::percentile_stretch(h, 1, 99), host::frontend::PreprocessOptions{});
  host::frontend::Gray8 g;
  g.width = full.width / 32 * 32;
  g.height = full.height / 32 * 32;
  if (!g.width || !g.height) throw std::invalid_argument("the frame is smaller than 32x32");
  for (int y = 0; y < g.height; ++y)
    g.pixels.insert(g.pixels.end(), full.pixels.begin() + y * full.width,
                    full.pixels.begin() + y * full.width + g.width);
  return g;
}

// Where one pair's time goes: each kernel's device time in one more run of the network itself.
nlohmann::json lighterglue_kernels(engine::Context& context, const kernels::nn::LighterGlueWeights& weights,
                                   const host::frontend::ImageFeatures& f,
                                   const host::frontend::Gray8& frame) {
  const kernels::LighterGlueNetwork network(context, weights);
  const host::nn::LighterGlueInputs in =
      host::nn::lighterglue_inputs(f, frame.width, frame.height, network.descriptor_width());
  nlohmann::json out = nlohmann::json::array();
  for (const engine::KernelTime& k :
       network.match(in.keypoints, in.descriptors, in.keypoints, in.descriptors).kernel_times)
    out.push_back({{"kernel", k.name}, {"dispatches", k.dispatches}, {"ms", k.ms}});
  return out;
}

void run_bench_features(const BenchFeaturesOptions& o) {
  if (o.runs < 1) throw std::invalid_argument("--runs must be at least 1");
  const host::frontend::Gray8 frame = load_frame(o.image);
  nlohmann::json rows = nlohmann::json::array();
  for (const char* name : {"orb", "sift", "akaze"}) {
    host::frontend::FeatureOptions f;
    f.type = host::frontend::parse_feature_type(name);
    std::vector<double> ms;
    size_t keypoints = 0;
    for (uint32_t r = 0; r <= o.runs; ++r) {
      const double t =
          time_ms([&] { keypoints = host::frontend::detect_features(frame, f).keypoints.size(); });
      if (r) ms.push_back(t);
    }
    rows.push_back(
        {{"detector", name}, {"where", "CPU (OpenCV)"}, {"ms", median(ms)}, {"keypoints", keypoints}});
  }
  const kernels::nn::XfeatWeights weights = host::nn::xfeat_weights(host::nn::xfeat_model(o.model));
  const std::vector<float> input = host::nn::xfeat_input(frame);
  const auto shared_context = std::make_shared<engine::Context>();
  engine::Context& context = *shared_context;
  const kernels::XfeatNetwork network(context, weights);
  std::vector<double> ms;
  std::map<std::string, std::vector<double>> kernel_ms;  // the device's time per kernel, each run
  std::map<std::string, uint32_t> kernel_dispatches;
  for (uint32_t r = 0; r <= o.runs; ++r) {
    kernels::XfeatDeviceOutputs out;
    const double t =
        time_ms([&] { out = network.run(input, uint32_t(frame.height), uint32_t(frame.width)); });
    if (!r) continue;
    ms.push_back(t);
    for (const engine::KernelTime& k : out.kernel_times) {
      kernel_ms[k.name].push_back(k.ms);
      kernel_dispatches[k.name] = k.dispatches;
    }
  }
  // Where the network's time goes: each kernel's device time (timestamps around each dispatch).
  nlohmann::json network_kernels = nlohmann::json::array();
  for (const auto& [name, times] : kernel_ms)
    network_kernels.push_back(
        {{"kernel", name}, {"dispatches", kernel_dispatches[name]}, {"ms", median(times)}});
  rows.push_back({{"detector", "xfeat network"},
                  {"where", "device: " + context.info().name},
                  {"ms", median(ms)},
                  {"kernels", network_kernels}});
  // What the front end pays per frame: normalization, network, keypoints, descriptors, grid bucketing; also
  // with the frame enlarged 2 and 3 times first (`match --xfeat-scale`).
  const host::frontend::LearnedDetector xfeat =
      host::nn::make_xfeat_detector(shared_context, weights, host::frontend::FeatureOptions{});
  for (const int scale : {1, 2, 3}) {
    host::frontend::FeatureOptions scaled;
    scaled.xfeat_scale = scale;
    const host::frontend::LearnedDetector detector =
        scale == 1 ? xfeat : host::nn::make_xfeat_detector(shared_context, weights, scaled);
    std::vector<double> detect_ms;
    size_t xfeat_keypoints = 0;
    for (uint32_t r = 0; r <= o.runs; ++r) {
      const double t = time_ms([&] { xfeat_keypoints = detector(frame).keypoints.size(); });
      if (r) detect_ms.push_back(t);
    }
    rows.push_back({{"detector", scale == 1 ? "xfeat" : "xfeat x" + std::to_string(scale)},
                    {"where", "device: network, keypoints, descriptors" +
                                  (scale == 1 ? std::string() : ", input x" + std::to_string(scale))},
                    {"ms", median(detect_ms)},
                    {"keypoints", xfeat_keypoints}});
  }
  // LighterGlue per pair of frames: attention is quadratic in the keypoints, so at 1000 and at all of them
  // (the frame matched with itself: the time does not depend on the content).
  const host::frontend::ImageFeatures detected = xfeat(frame);
  const kernels::nn::LighterGlueWeights lighterglue_weights =
      host::nn::lighterglue_weights(host::nn::lighterglue_model());
  const host::frontend::LearnedMatcher lighterglue =
      host::nn::make_lighterglue_matcher(shared_context, lighterglue_weights, 0.1);
  for (const size_t n : {size_t{1000}, detected.keypoints.size()}) {
    host::frontend::ImageFeatures f = detected;
    f.keypoints.resize(std::min(n, f.keypoints.size()));
    f.descriptors.resize(f.keypoints.size() * size_t(f.descriptor_bytes));
    std::vector<double> pair_ms;
    size_t matches = 0;
    for (uint32_t r = 0; r <= o.runs; ++r) {
      const double t = time_ms([&] { matches = lighterglue(f, f, frame.width, frame.height).size(); });
      if (r) pair_ms.push_back(t);
    }
    rows.push_back({{"detector", "lighterglue"},
                    {"where", "device: one pair, " + std::to_string(f.keypoints.size()) + " keypoints each"},
                    {"ms", median(pair_ms)},
                    {"matches", matches},
                    {"kernels", lighterglue_kernels(context, lighterglue_weights, f, frame)}});
    if (f.keypoints.size() == detected.keypoints.size()) break;
  }
  kernels::nn::FeatureMap image(1, frame.height, frame.width);
  image.values.assign(input.begin(), input.end());
  const kernels::nn::XfeatReference reference(weights);
  const double cpu_ms = time_ms([&] { reference.run(image); });
  rows.push_back(
      {{"detector", "xfeat network"}, {"where", "CPU double reference, 1 thread"}, {"ms", cpu_ms}});
  if (o.json) {
    std::cout << nlohmann::json{{"width", frame.width},
                                {"height", frame.height},
                                {"runs", o.runs},
                                {"rows", rows},
                                {"device", device_json(context.info())}}
                     .dump(2)
              << "\n";
    return;
  }
  std::cout << "bench features: " << frame.width << "x" << frame.height << ", median of " << o.runs
            << " runs after one warm-up (the CPU reference: one run)\n";
  for (const auto& r : rows) {
    std::cout << "  " << std::left << std::setw(14) << r["detector"].get<std::string>() << std::setw(48)
              << r["where"].get<std::string>() << std::right << std::fixed << std::setprecision(1)
              << std::setw(9) << r["ms"].get<double>() << " ms"
              << (r.contains("keypoints") ? "  " + std::to_string(r["keypoints"].get<size_t>()) + " keypoints"
                                          : "")
              << "\n";
    if (!r.contains("kernels")) continue;
    for (const auto& k : r["kernels"])
      std::cout << "    " << std::left << std::setw(60)
                << (k["kernel"].get<std::string>() + ", " + std::to_string(k["dispatches"].get<uint32_t>()) +
                    " dispatches")
                << std::right << std::setw(9) << k["ms"].get<double>() << " ms on the device\n";
  }
}

}  // namespace

void add_bench_features_command(CLI::App& bench) {
  auto o = std::make_shared<BenchFeaturesOptions>();
  CLI::App* cmd =
      bench.add_subcommand("features", "Milliseconds per frame of each detector, XFeat on the device");
  cmd->add_option("--image", o->image, "A one-channel 8- or 16-bit frame (default: a 640x512 pattern)")
      ->check(CLI::ExistingFile);
  cmd->add_option("--model", o->model, "XFeat's ONNX model (default: the one embedded in the binary)")
      ->check(CLI::ExistingFile);
  cmd->add_option("--runs", o->runs, "Timed runs after one warm-up")->capture_default_str();
  cmd->add_flag("--json", o->json, "Print one JSON object");
  cmd->callback([o] { run_bench_features(*o); });
}

}  // namespace litgs::tools
