// XFeat's post-processing on the device (kernels/nn/nn_keypoints.comp, XfeatNetwork::detect) against its
// double-precision CPU reference (kernels/nn/xfeat_keypoints_reference.h), validation layer on. Each op is
// fed the device's own input to the op, so that it is compared alone: the heat map within 1e-6, scores within
// 1e-5 of the largest and the same pixels kept, normalized channels within 1e-6, descriptors within 1e-5. The
// whole detection on a DUNR crop against the CPU network and post-processing: the same keypoints but for
// near-ties, descriptors within 1e-3, and a selection of them described alone. Hard cases: determinism, a
// uniform image, the smallest size.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <random>
#include <set>
#include <vector>

#include "engine/buffer.h"
#include "engine/sequence.h"
#include "gpu_test.h"
#include "host/nn/xfeat_weights.h"
#include "io/image.h"
#include "io/onnx_model.h"
#include "kernels/nn/nn_keypoints.h"
#include "kernels/nn/xfeat.h"
#include "kernels/nn/xfeat_keypoints_reference.h"
#include "kernels/nn/xfeat_reference.h"

namespace litgs {
namespace {

using engine::DeviceArray;
using kernels::nn::FeatureMap;

FeatureMap random_map(int c, int h, int w, uint32_t seed, float sd) {
  std::mt19937 rng(seed);
  std::normal_distribution<float> n(0.0f, sd);
  FeatureMap m(c, h, w);
  for (double& v : m.values) v = n(rng);
  return m;
}

std::vector<float> as_float(const FeatureMap& m) {
  return {m.values.begin(), m.values.end()};
}

FeatureMap as_map(const std::vector<float>& v, int c, int h, int w) {
  FeatureMap m(c, h, w);
  std::copy(v.begin(), v.end(), m.values.begin());
  return m;
}

class NnKeypointsTest : public testing::GpuTest {};

TEST_F(NnKeypointsTest, EachOpMatchesItsReference) {
  const int h = 6, w = 10, H = 8 * h, W = 8 * w;
  const FeatureMap logits = random_map(65, h, w, 3, 3.0f);  // peaked softmaxes: heat above 0.05 somewhere
  FeatureMap reliability = random_map(1, h, w, 4, 1.0f);
  for (double& r : reliability.values) r = 1 / (1 + std::exp(-r));
  const FeatureMap features = random_map(64, h, w, 5, 1.0f);
  DeviceArray<float> d_logits(context(), "test: logits", logits.values.size()),
      d_rel(context(), "test: reliability", reliability.values.size()),
      d_features(context(), "test: features", features.values.size()),
      d_heat(context(), "test: heat", size_t(H) * W), d_scores(context(), "test: scores", size_t(H) * W),
      d_norm(context(), "test: normalized", features.values.size());
  d_logits.upload(as_float(logits));
  d_rel.upload(as_float(reliability));
  d_features.upload(as_float(features));
  const kernels::KeypointKernel kernel(context());
  engine::Sequence s(context());
  kernel.heatmap(s, d_logits.buffer(), d_heat.buffer(), h, w);
  kernel.scores(s, d_heat.buffer(), d_rel.buffer(), d_scores.buffer(), h, w, 0.05f, 5);
  kernel.normalize(s, d_features.buffer(), d_norm.buffer(), {64, uint32_t(h), uint32_t(w)});
  s.submit_and_wait();

  const std::vector<float> heat = d_heat.download();
  const FeatureMap ref_heat = kernels::nn::keypoint_heatmap(logits);
  for (size_t i = 0; i < heat.size(); ++i) ASSERT_NEAR(heat[i], ref_heat.values[i], 1e-6) << i;

  // Scores from the device's own heat, so that a near-tie rounded differently cannot move a keypoint.
  const std::vector<float> scores = d_scores.download();
  const FeatureMap ref_scores =
      kernels::nn::keypoint_scores(as_map(heat, 1, H, W), reliability, kernels::nn::XfeatKeypointOptions{});
  size_t kept = 0;
  for (size_t i = 0; i < scores.size(); ++i) {
    ASSERT_EQ(scores[i] > 0, ref_scores.values[i] > 0) << i;
    ASSERT_NEAR(scores[i], ref_scores.values[i], 1e-5) << i;
    kept += scores[i] > 0;
  }
  EXPECT_GT(kept, 20u);

  const std::vector<float> normalized = d_norm.download();
  const FeatureMap ref_norm = kernels::nn::normalize_channels(features);
  for (size_t i = 0; i < normalized.size(); ++i) ASSERT_NEAR(normalized[i], ref_norm.values[i], 1e-6) << i;

  // Descriptors at keypoints anywhere, the image's corners and edges among them.
  std::vector<kernels::nn::ScoredKeypoint> at = {{0, 0, 1}, {float(W - 1), float(H - 1), 1}, {0, 20, 1}};
  std::mt19937 rng(9);
  for (int k = 0; k < 60; ++k)
    at.push_back({float(std::uniform_int_distribution<int>(0, W - 1)(rng)),
                  float(std::uniform_int_distribution<int>(0, H - 1)(rng)), 1});
  std::vector<float> xy;
  for (const auto& k : at) xy.insert(xy.end(), {k.x, k.y});
  DeviceArray<float> d_xy(context(), "test: xy", xy.size()),
      d_desc(context(), "test: descriptors", at.size() * 64);
  d_xy.upload(xy);
  engine::Sequence s2(context());
  kernel.descriptors(s2, d_norm.buffer(), d_xy.buffer(), d_desc.buffer(), {64, uint32_t(h), uint32_t(w)},
                     uint32_t(at.size()));
  s2.submit_and_wait();
  const std::vector<float> desc = d_desc.download();
  const std::vector<double> ref_desc =
      kernels::nn::sample_descriptors(as_map(normalized, 64, h, w), at, W, H);
  for (size_t i = 0; i < desc.size(); ++i) ASSERT_NEAR(desc[i], ref_desc[i], 1e-5) << i;

  EXPECT_THROW(kernel.scores(s2, d_heat.buffer(), d_rel.buffer(), d_scores.buffer(), h, w, 0.05f, 4),
               std::invalid_argument);
  EXPECT_THROW(kernel.heatmap(s2, d_rel.buffer(), d_heat.buffer(), h, w), std::invalid_argument);
}

// A DUNR frame cropped to 128x128, normalized as the front end hands it over.
std::vector<float> dunr_crop() {
  const io::Image raw = io::read_image(std::string(LITGS_TEST_DATA_DIR) +
                                       "/thermitage-dunr/radjpg/22-18-41-880-radiometric.jpg");
  std::vector<double> v;
  for (int y = 200; y < 328; ++y)
    for (int x = 250; x < 378; ++x) v.push_back(raw.data[size_t(y) * raw.width + x]);
  double mean = 0, sq = 0;
  for (double p : v) mean += p;
  mean /= double(v.size());
  for (double p : v) sq += (p - mean) * (p - mean);
  const double sd = std::sqrt(sq / double(v.size()));
  std::vector<float> out;
  for (double p : v) out.push_back(float((p - mean) / sd));
  return out;
}

TEST_F(NnKeypointsTest, DetectionMatchesTheCpuNetworkAndPostProcessing) {
  const kernels::nn::XfeatWeights weights = host::nn::xfeat_weights(
      io::read_onnx_model(std::string(LITGS_NN_MODELS) + "/xfeat/xfeat_640x640.onnx"));
  const kernels::XfeatNetwork network(context(), weights);
  const std::vector<float> image = dunr_crop();
  kernels::nn::XfeatKeypointOptions o;
  o.top_k = 200;
  const kernels::XfeatDetections device = network.detect(image, 128, 128, o);
  FeatureMap input(1, 128, 128);
  std::copy(image.begin(), image.end(), input.values.begin());
  const kernels::nn::XfeatOutputs maps = kernels::nn::XfeatReference(weights).run(input);
  const kernels::nn::XfeatKeypoints cpu =
      kernels::nn::detect_keypoints(maps.features, maps.keypoints, maps.heatmap, o);
  ASSERT_GT(cpu.keypoints.size(), 50u);
  ASSERT_EQ(device.descriptors.size(), device.keypoints.size() * 64);
  std::set<std::pair<int, int>> cpu_at;
  for (const auto& k : cpu.keypoints) cpu_at.insert({int(k.x), int(k.y)});
  size_t common = 0;
  for (size_t i = 0; i < device.keypoints.size(); ++i) {
    const auto& k = device.keypoints[i];
    const auto it = std::find_if(cpu.keypoints.begin(), cpu.keypoints.end(),
                                 [&](const auto& c) { return c.x == k.x && c.y == k.y; });
    if (it == cpu.keypoints.end()) continue;
    ++common;
    const size_t j = size_t(it - cpu.keypoints.begin());
    EXPECT_NEAR(k.score, it->score, 1e-4);
    for (int c = 0; c < 64; ++c)
      ASSERT_NEAR(device.descriptors[i * 64 + c], cpu.descriptors[j * 64 + c], 1e-3);
  }
  // float against double: a keypoint at a near-tie of the NMS or of the 200th score may differ.
  EXPECT_GE(double(common), 0.97 * double(cpu.keypoints.size()));
  std::printf("xfeat detect on a 128x128 DUNR crop: %zu device keypoints, %zu CPU, %zu in common\n",
              device.keypoints.size(), cpu.keypoints.size(), common);

  // Deterministic: the same image gives the same keypoints and descriptors, bit for bit.
  const kernels::XfeatDetections again = network.detect(image, 128, 128, o);
  ASSERT_EQ(again.keypoints.size(), device.keypoints.size());
  for (size_t i = 0; i < again.keypoints.size(); ++i) {
    EXPECT_EQ(again.keypoints[i].x, device.keypoints[i].x);
    EXPECT_EQ(again.keypoints[i].y, device.keypoints[i].y);
    EXPECT_EQ(again.keypoints[i].score, device.keypoints[i].score);
  }
  EXPECT_EQ(again.descriptors, device.descriptors);

  // A selection (the front end's grid bucketing) describes only the keypoints it names, in its order, with
  // the descriptors the whole detection gives them; an index beyond the candidates is refused.
  const std::vector<size_t> picked = {7, 0, 42};
  const kernels::XfeatDetections some =
      network.detect(image, 128, 128, o, [&](const auto&) { return picked; });
  ASSERT_EQ(some.keypoints.size(), picked.size());
  ASSERT_EQ(some.descriptors.size(), picked.size() * 64);
  for (size_t n = 0; n < picked.size(); ++n) {
    EXPECT_EQ(some.keypoints[n].x, device.keypoints[picked[n]].x);
    EXPECT_EQ(some.keypoints[n].y, device.keypoints[picked[n]].y);
    for (int c = 0; c < 64; ++c)
      EXPECT_EQ(some.descriptors[n * 64 + c], device.descriptors[picked[n] * 64 + c]);
  }
  EXPECT_THROW(
      network.detect(image, 128, 128, o, [](const auto& all) { return std::vector<size_t>{all.size()}; }),
      std::out_of_range);
}

TEST_F(NnKeypointsTest, AUniformImageGivesNoKeypointsAndTheSmallestSizeWorks) {
  const kernels::nn::XfeatWeights weights = host::nn::xfeat_weights(
      io::read_onnx_model(std::string(LITGS_NN_MODELS) + "/xfeat/xfeat_640x640.onnx"));
  const kernels::XfeatNetwork network(context(), weights);
  const kernels::XfeatDetections uniform = network.detect(std::vector<float>(64 * 64, 0.0f), 64, 64);
  EXPECT_TRUE(uniform.keypoints.empty());
  const FeatureMap noise = random_map(1, 32, 32, 11, 1.0f);
  const kernels::XfeatDetections small = network.detect(as_float(noise), 32, 32);
  for (float d : small.descriptors) ASSERT_TRUE(std::isfinite(d));
  for (const auto& k : small.keypoints) {
    EXPECT_GT(k.score, 0.0f);
    EXPECT_LT(k.x, 32.0f);
    EXPECT_LT(k.y, 32.0f);
  }
  EXPECT_THROW(network.detect(std::vector<float>(48 * 32, 0.0f), 48, 32), std::invalid_argument);
}

}  // namespace
}  // namespace litgs
