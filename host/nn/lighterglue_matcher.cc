#include "host/nn/lighterglue_matcher.h"

#include <cstring>
#include <mutex>
#include <stdexcept>
#include <string>

#include "kernels/nn/lighterglue.h"
#include "kernels/nn/lighterglue_reference.h"

namespace litgs::host::nn {

LighterGlueInputs lighterglue_inputs(const frontend::ImageFeatures& f, int width, int height,
                                     size_t descriptor_width) {
  if (!f.keypoints.empty() &&
      (!f.float_descriptors || size_t(f.descriptor_bytes) != descriptor_width * sizeof(float)))
    throw std::invalid_argument("the lighterglue matcher needs " + std::to_string(descriptor_width) +
                                " float descriptors per keypoint (features xfeat)");
  std::vector<float> xy;
  for (const io::SfmKeypoint& k : f.keypoints) xy.insert(xy.end(), {k.x, k.y});
  const kernels::nn::Matrix normalized = kernels::nn::normalize_keypoints(xy, width, height);
  LighterGlueInputs in;
  in.keypoints.assign(normalized.values.begin(), normalized.values.end());
  in.descriptors.resize(f.keypoints.size() * descriptor_width);
  if (!in.descriptors.empty())
    std::memcpy(in.descriptors.data(), f.descriptors.data(), in.descriptors.size() * sizeof(float));
  return in;
}

namespace {

struct LighterGlueMatcher {
  std::shared_ptr<engine::Context> context;
  std::unique_ptr<kernels::LighterGlueNetwork> network;
  double min_score = 0.1;
  std::mutex device;  // one submit at a time on the shared context

  std::vector<std::array<uint32_t, 2>> operator()(const frontend::ImageFeatures& a,
                                                  const frontend::ImageFeatures& b, int width, int height) {
    const LighterGlueInputs ia = lighterglue_inputs(a, width, height, network->descriptor_width()),
                            ib = lighterglue_inputs(b, width, height, network->descriptor_width());
    kernels::LighterGlueMatches m;
    {
      std::lock_guard<std::mutex> lock(device);
      m = network->match(ia.keypoints, ia.descriptors, ib.keypoints, ib.descriptors);
    }
    std::vector<std::array<uint32_t, 2>> out;
    for (size_t i = 0; i < m.matches.size(); ++i)
      if (m.match_scores[i] > min_score)
        out.push_back({uint32_t(m.matches[i][0]), uint32_t(m.matches[i][1])});
    return out;
  }
};

}  // namespace

frontend::LearnedMatcher make_lighterglue_matcher(std::shared_ptr<engine::Context> context,
                                                  const kernels::nn::LighterGlueWeights& weights,
                                                  double min_score) {
  auto matcher = std::make_shared<LighterGlueMatcher>();
  matcher->network = std::make_unique<kernels::LighterGlueNetwork>(*context, weights);
  matcher->context = std::move(context);
  matcher->min_score = min_score;
  return [matcher](const frontend::ImageFeatures& a, const frontend::ImageFeatures& b, int width,
                   int height) { return (*matcher)(a, b, width, height); };
}

}  // namespace litgs::host::nn
