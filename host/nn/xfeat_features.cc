#include "host/nn/xfeat_features.h"

#include <cmath>
#include <cstring>
#include <mutex>
#include <stdexcept>
#include <string>

#include "host/frontend/features.h"
#include "host/frontend/preprocess.h"
#include "host/nn/embedded_models.h"
#include "host/nn/lighterglue_matcher.h"
#include "host/nn/lighterglue_weights.h"
#include "host/nn/xfeat_weights.h"
#include "kernels/nn/xfeat.h"

namespace litgs::host::nn {
namespace {

constexpr int kDescriptorFloats = 64;
constexpr float kCellPx = 8;  // the network's cell: the keypoint's scale as the front end records it

// The network on one context; the device's queue takes one detection at a time.
struct XfeatDetector {
  std::shared_ptr<engine::Context> context;
  std::unique_ptr<kernels::XfeatNetwork> network;
  frontend::FeatureOptions options;
  std::mutex device;

  frontend::ImageFeatures operator()(const frontend::Gray8& frame) {
    frontend::ImageFeatures f;
    f.float_descriptors = true;
    f.descriptor_bytes = kDescriptorFloats * int(sizeof(float));
    if (frame.pixels.empty()) return f;
    const double scale = options.xfeat_scale;
    const int width = int(std::lround(frame.width * scale)) / 32 * 32,
              height = int(std::lround(frame.height * scale)) / 32 * 32;
    if (!width || !height)
      throw std::invalid_argument(
          "xfeat: a " + std::to_string(frame.width) + "x" + std::to_string(frame.height) + " frame" +
          (scale != 1 ? " at xfeat_scale " + std::to_string(scale) : "") + " is smaller than 32x32");
    const bool resized = width != frame.width || height != frame.height;
    const std::vector<float> input =
        xfeat_input(resized ? frontend::resize_gray8(frame, width, height) : frame);
    kernels::nn::XfeatKeypointOptions k;
    // Candidates beyond the budget, so that the grid bucketing has some to spread.
    k.top_k = static_cast<uint32_t>(4 * options.max_keypoints);
    // Back to the frame's pixels, centres at integers on both sides of the half-pixel resize.
    const float sx = float(frame.width) / float(width), sy = float(frame.height) / float(height);
    // The grid bucketing chooses among the candidates before the descriptors are sampled.
    const auto bucket = [&](const std::vector<kernels::nn::ScoredKeypoint>& candidates) {
      std::vector<float> x, y, score;
      for (const auto& p : candidates) {
        x.push_back(p.x);
        y.push_back(p.y);
        score.push_back(p.score);
      }
      return frontend::bucket_keypoints(x, y, score, width, height, options.max_keypoints, options.grid_cols,
                                        options.grid_rows);
    };
    kernels::XfeatDetections d;
    {
      const std::lock_guard<std::mutex> lock(device);
      d = network->detect(input, uint32_t(height), uint32_t(width), k, bucket);
    }
    f.descriptors.resize(d.keypoints.size() * size_t(f.descriptor_bytes));
    for (size_t n = 0; n < d.keypoints.size(); ++n) {
      const kernels::nn::ScoredKeypoint& p = d.keypoints[n];
      f.keypoints.push_back({(p.x + 0.5f) * sx - 0.5f, (p.y + 0.5f) * sy - 0.5f, kCellPx * sx, -1});
      std::memcpy(f.descriptors.data() + n * size_t(f.descriptor_bytes),
                  d.descriptors.data() + n * kDescriptorFloats, size_t(f.descriptor_bytes));
    }
    return f;
  }
};

}  // namespace

std::vector<float> xfeat_input(const frontend::Gray8& image) {
  double mean = 0, variance = 0;
  for (uint8_t p : image.pixels) mean += p / 255.0;
  mean /= double(std::max<size_t>(image.pixels.size(), 1));
  for (uint8_t p : image.pixels) variance += (p / 255.0 - mean) * (p / 255.0 - mean);
  variance /= double(std::max<size_t>(image.pixels.size(), 1));
  const double scale = 1 / std::sqrt(variance + 1e-5);
  std::vector<float> out;
  out.reserve(image.pixels.size());
  for (uint8_t p : image.pixels) out.push_back(static_cast<float>((p / 255.0 - mean) * scale));
  return out;
}

frontend::LearnedDetector make_xfeat_detector(std::shared_ptr<engine::Context> context,
                                              const kernels::nn::XfeatWeights& weights,
                                              const frontend::FeatureOptions& options) {
  options.check();
  auto detector = std::make_shared<XfeatDetector>();
  detector->network = std::make_unique<kernels::XfeatNetwork>(*context, weights);
  detector->context = std::move(context);
  detector->options = options;
  return [detector](const frontend::Gray8& frame) { return (*detector)(frame); };
}

frontend::FrontendOptions with_learned_detector(frontend::FrontendOptions options,
                                                const std::filesystem::path& model,
                                                const std::filesystem::path& lighterglue) {
  const bool learned_matcher = options.match.matcher == frontend::Matcher::kLighterGlue;
  if (options.features.type != frontend::FeatureType::kXfeat && !learned_matcher) return options;
  auto context = std::make_shared<engine::Context>();
  if (options.features.type == frontend::FeatureType::kXfeat)
    options.learned_detector =
        make_xfeat_detector(context, xfeat_weights(xfeat_model(model)), options.features);
  if (learned_matcher)
    options.learned_matcher = make_lighterglue_matcher(
        context, lighterglue_weights(lighterglue_model(lighterglue)), options.match.min_score);
  return options;
}

}  // namespace litgs::host::nn
