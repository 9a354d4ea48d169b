// kernels/nn's double-precision references: single operations on cases worked by hand, and XFeat as a whole
// against onnxruntime's float32 outputs (tests/data/xfeat/reference.json, made by make_reference.js there).
#include <gtest/gtest.h>

#include <cmath>
#include <fstream>
#include <nlohmann/json.hpp>

#include "host/nn/xfeat_weights.h"
#include "io/error.h"
#include "kernels/nn/xfeat_reference.h"

namespace litgs::kernels::nn {
namespace {

const std::string kModel = std::string(LITGS_NN_MODELS) + "/xfeat/xfeat_640x640.onnx";
const std::string kReference = std::string(LITGS_TEST_DATA_DIR) + "/xfeat/reference.json";

ConvWeights weights(uint32_t out, uint32_t in, uint32_t k, std::vector<float> w, std::vector<float> b,
                    uint32_t stride, uint32_t pad) {
  ConvWeights c;
  c.out_channels = out;
  c.in_channels = in;
  c.kernel = k;
  c.weight = std::move(w);
  c.bias = std::move(b);
  c.stride = stride;
  c.pad = pad;
  return c;
}

XfeatReference load_xfeat() {
  return XfeatReference(host::nn::xfeat_weights(io::read_onnx_model(kModel)));
}

TEST(NnReference, ConvolutionWithStrideAndPaddingByHand) {
  // A 3x3 input 1..9, a 3x3 kernel of ones, bias 0.5, stride 2, pad 1: 2x2 outputs, each the sum of the
  // input pixels its window covers.
  FeatureMap in(1, 3, 3);
  for (int i = 0; i < 9; ++i) in.values[i] = i + 1;
  const FeatureMap out = conv2d(in, weights(1, 1, 3, std::vector<float>(9, 1.0f), {0.5f}, 2, 1));
  ASSERT_EQ(out.height, 2);
  ASSERT_EQ(out.width, 2);
  EXPECT_DOUBLE_EQ(out.at(0, 0, 0), 1 + 2 + 4 + 5 + 0.5);
  EXPECT_DOUBLE_EQ(out.at(0, 0, 1), 2 + 3 + 5 + 6 + 0.5);
  EXPECT_DOUBLE_EQ(out.at(0, 1, 1), 5 + 6 + 8 + 9 + 0.5);
  EXPECT_THROW(conv2d(in, weights(1, 2, 3, std::vector<float>(18, 1.0f), {0.0f}, 1, 1)),
               std::invalid_argument);
}

TEST(NnReference, BilinearResizeHalfPixelAndUnfoldByHand) {
  // 2 -> 4 columns with half-pixel centres: sources -0.25 (clamped to 0), 0.25, 0.75, 1.25 (clamped to 1).
  FeatureMap in(1, 1, 2);
  in.values = {10, 20};
  const FeatureMap up = resize_bilinear(in, 1, 4);
  EXPECT_DOUBLE_EQ(up.at(0, 0, 0), 10);
  EXPECT_DOUBLE_EQ(up.at(0, 0, 1), 12.5);
  EXPECT_DOUBLE_EQ(up.at(0, 0, 2), 17.5);
  EXPECT_DOUBLE_EQ(up.at(0, 0, 3), 20);
  FeatureMap image(1, 4, 4);
  for (int i = 0; i < 16; ++i) image.values[i] = i;
  const FeatureMap u = unfold(image, 2);
  ASSERT_EQ(u.channels, 4);
  EXPECT_DOUBLE_EQ(u.at(0, 1, 1), 10);  // block (1,1)'s top-left: row 2, column 2
  EXPECT_DOUBLE_EQ(u.at(3, 1, 1), 15);  // its bottom-right
  EXPECT_DOUBLE_EQ(u.at(1, 0, 1), 3);   // block (0,1)'s top-right: row 0, column 3
}

// make_reference.js's input_value, normalized the same way (double, then float32 as the runtime took it).
FeatureMap pattern(int k, int size) {
  FeatureMap m(1, size, size);
  double mean = 0;
  for (int y = 0; y < size; ++y)
    for (int x = 0; x < size; ++x) {
      const double v = k == 0 ? std::sin(0.05 * x) * std::cos(0.031 * y) + 0.002 * x
                              : std::sin(0.11 * (x + 0.7 * y)) + 0.5 * std::cos(0.023 * x * (1 + 0.001 * y)) +
                                    (((x >> 5) + (y >> 5)) % 2 ? 0.8 : -0.3);
      m.at(0, y, x) = v;
      mean += v;
    }
  mean /= double(size) * size;
  double variance = 0;
  for (double v : m.values) variance += (v - mean) * (v - mean);
  const double sd = std::sqrt(variance / (double(size) * size));
  for (double& v : m.values) v = static_cast<float>((v - mean) / sd);
  return m;
}

// The runtime's flat index into its output layout (NHWC for features and keypoints, NCHW for the heatmap).
double element(const FeatureMap& m, bool nhwc, size_t i) {
  if (!nhwc) return m.values[i];
  const size_t c = i % m.channels, x = (i / m.channels) % m.width, y = i / (size_t(m.channels) * m.width);
  return m.at(int(c), int(y), int(x));
}

TEST(XfeatReference, MatchesOnnxRuntimeOnBothPatterns) {
  const XfeatReference xfeat = load_xfeat();
  std::ifstream in(kReference);
  ASSERT_TRUE(in) << kReference;
  const nlohmann::json ref = nlohmann::json::parse(in);
  const int size = ref["size"], stride = ref["stride"];
  for (const auto& p : ref["patterns"]) {
    const XfeatOutputs out = xfeat.run(pattern(p["pattern"], size));
    const std::pair<const char*, const FeatureMap*> outputs[] = {{"output_feats", &out.features},
                                                                 {"output_keypoints", &out.keypoints},
                                                                 {"output_heatmap", &out.heatmap}};
    for (const auto& [name, map] : outputs) {
      const auto& values = p["outputs"][name]["values"];
      const bool nhwc = std::string(name) != "output_heatmap";
      // float32 against double through 20 layers: within 1e-3 of the output's own RMS, element by element.
      double rms = 0, worst = 0;
      for (const auto& v : values) rms += v.get<double>() * v.get<double>();
      rms = std::sqrt(rms / static_cast<double>(values.size()));
      for (size_t k = 0; k < values.size(); ++k)
        worst = std::max(worst, std::abs(element(*map, nhwc, k * stride) - values[k].get<double>()));
      EXPECT_LT(worst, 1e-3 * rms) << name << " pattern " << p["pattern"] << ": worst " << worst << ", rms "
                                   << rms;
      std::printf("xfeat %s pattern %d: worst |difference| %.3g, output RMS %.3g\n", name,
                  p["pattern"].get<int>(), worst, rms);
    }
  }
}

TEST(XfeatReferenceHardCases, UniformSmallestAndRefusedSizes) {
  const XfeatReference xfeat = load_xfeat();
  FeatureMap uniform(1, 32, 32);  // a normalized uniform image is all zeros
  const XfeatOutputs out = xfeat.run(uniform);
  EXPECT_EQ(out.features.width, 4);
  EXPECT_EQ(out.keypoints.channels, 65);
  for (const FeatureMap* m : {&out.features, &out.keypoints, &out.heatmap})
    for (double v : m->values) ASSERT_TRUE(std::isfinite(v));
  EXPECT_THROW(xfeat.run(FeatureMap(1, 40, 32)), std::invalid_argument);
  EXPECT_THROW(xfeat.run(FeatureMap(1, 0, 0)), std::invalid_argument);
}

TEST(XfeatReferenceHardCases, ALighterGlueModelIsNotTakenForXfeat) {
  const std::string other = std::string(LITGS_NN_MODELS) + "/lighterglue/lighterglue_L3.onnx";
  try {
    host::nn::xfeat_weights(io::read_onnx_model(other));
    FAIL() << "LighterGlue accepted as XFeat";
  } catch (const io::IoError& e) {
    EXPECT_NE(std::string(e.what()).find("XFeat"), std::string::npos) << e.what();
  }
}

}  // namespace
}  // namespace litgs::kernels::nn
