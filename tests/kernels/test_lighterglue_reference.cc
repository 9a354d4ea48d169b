// LighterGlue's double-precision reference (kernels/nn/lighterglue_reference.h, attention_reference.h):
// single operations on cases worked by hand, the weights' loader on a wrong model, and the whole matcher
// against onnxruntime's float32 outputs (tests/data/lighterglue/reference.json, made by make_reference.js
// there, whose input formulas this file repeats). Tolerances (double against float32): each score within
// 3e-3 of max(1, |score|), the same matches, their scores within 1e-3 relative. Float32 is the limit here:
// onnxruntime's outputs with its graph optimizations on and off differ by 7.8e-4 of max(1, |score|), and
// this reference from them by 1.5e-3 (scores reach -168), where a one-ulp change of the inputs moves the
// double reference by 9e-7.
#include <gtest/gtest.h>

#include <cmath>
#include <fstream>
#include <nlohmann/json.hpp>

#include "host/nn/lighterglue_weights.h"
#include "io/error.h"
#include "kernels/nn/lighterglue_reference.h"
#include "tests/support/lighterglue_inputs.h"

namespace litgs::kernels::nn {
namespace {

const std::string kModel = std::string(LITGS_NN_MODELS) + "/lighterglue/lighterglue_L3.onnx";
const std::string kReference = std::string(LITGS_TEST_DATA_DIR) + "/lighterglue/reference.json";

using namespace testing::lighterglue_inputs;

LighterGlueWeights load() {
  return host::nn::lighterglue_weights(io::read_onnx_model(kModel));
}

TEST(AttentionReference, OperationsByHand) {
  Matrix x(1, 4);
  x.values = {1, 2, 3, 6};
  LayerNormWeights norm{{1, 1, 1, 2}, {0, 0, 0, 1}, 0.0};
  layer_norm(x, norm);  // mean 3, variance (4 + 1 + 0 + 9) / 4 = 3.5
  EXPECT_NEAR(x.at(0, 0), -2 / std::sqrt(3.5), 1e-15);
  EXPECT_NEAR(x.at(0, 3), 2 * 3 / std::sqrt(3.5) + 1, 1e-15);

  Matrix g(1, 3);
  g.values = {0, 1, -1};
  gelu(g);
  EXPECT_EQ(g.at(0, 0), 0.0);
  EXPECT_NEAR(g.at(0, 1), 0.8413447460685429, 1e-15);  // Phi(1)
  EXPECT_NEAR(g.at(0, 2), -0.15865525393145707, 1e-15);

  Matrix s(2, 2);
  s.values = {0, std::log(3.0), 1000, 1000};  // the second row would overflow without the shift
  const Matrix ls = log_softmax_rows(s);
  EXPECT_NEAR(ls.at(0, 0), std::log(0.25), 1e-15);
  EXPECT_NEAR(ls.at(1, 1), std::log(0.5), 1e-12);
  const Matrix lc = log_softmax_columns(s);
  EXPECT_NEAR(lc.at(1, 0), 0.0, 1e-12);  // 1000 against 0
  softmax_rows(s);
  EXPECT_NEAR(s.at(0, 1), 0.75, 1e-15);

  // Rotary: pair (a, b) turned by the frequency; position (1, 0) and weights [[pi/2], [0]] turn by 90 deg.
  Matrix p(1, 2);
  p.values = {1, 0};
  const Matrix f = rotary_frequencies(p, {float(M_PI / 2), 0.0f});
  Matrix r(1, 2);
  r.values = {1, 2};
  apply_rotary(r, f);
  EXPECT_NEAR(r.at(0, 0), -2, 1e-6);  // float pi/2
  EXPECT_NEAR(r.at(0, 1), 1, 1e-6);

  // Mutual best: row 0 and column 1 agree, row 1's best (column 1) prefers row 0.
  Matrix m(2, 2);
  m.values = {0.1, 0.9, 0.2, 0.8};
  std::vector<std::array<int, 2>> matches;
  std::vector<double> values;
  mutual_best(m, matches, values);
  ASSERT_EQ(matches.size(), 1u);
  EXPECT_EQ(matches[0], (std::array<int, 2>{0, 1}));
  EXPECT_NEAR(values[0], std::exp(0.9), 1e-15);

  EXPECT_THROW(multiply(Matrix(2, 3), Matrix(2, 3)), std::invalid_argument);
  const Matrix k = normalize_keypoints({0, 0, 640, 256}, 640, 512);
  EXPECT_DOUBLE_EQ(k.at(0, 0), -1.0);
  EXPECT_DOUBLE_EQ(k.at(0, 1), -0.8);
  EXPECT_DOUBLE_EQ(k.at(1, 0), 1.0);
  EXPECT_DOUBLE_EQ(k.at(1, 1), 0.0);
}

TEST(LighterGlueReference, WeightsLoadAndAWrongModelIsNamed) {
  const LighterGlueWeights w = load();
  EXPECT_EQ(w.layers.size(), 3u);
  EXPECT_EQ(w.dim(), 96u);
  EXPECT_EQ(w.position.size(), 96u);
  EXPECT_EQ(w.layers[2].cross_ffn.norm.scale.size(), 192u);
  try {
    host::nn::lighterglue_weights(
        io::read_onnx_model(std::string(LITGS_NN_MODELS) + "/xfeat/xfeat_640x640.onnx"));
    FAIL() << "the XFeat model was taken for LighterGlue";
  } catch (const io::IoError& e) {
    EXPECT_NE(std::string(e.what()).find("/net/input_proj/MatMul"), std::string::npos) << e.what();
  }
}

TEST(LighterGlueReference, MatchesOnnxRuntime) {
  std::ifstream file(kReference);
  ASSERT_TRUE(file) << kReference;
  const nlohmann::json ref = nlohmann::json::parse(file);
  const LighterGlueOutputs out =
      lighterglue(load(), keypoints0(), descriptors0(), keypoints1(), descriptors1());
  const std::vector<double> scores = ref["scores"]["values"].get<std::vector<double>>();
  ASSERT_EQ(scores.size(), out.scores.values.size());
  double worst = 0;
  for (size_t i = 0; i < scores.size(); ++i)
    worst = std::max(worst, std::abs(scores[i] - out.scores.values[i]) / std::max(1.0, std::abs(scores[i])));
  EXPECT_LT(worst, 3e-3);
  const std::vector<int> matches = ref["matches"].get<std::vector<int>>();
  const std::vector<double> values = ref["match_scores"].get<std::vector<double>>();
  ASSERT_EQ(out.matches.size() * 2, matches.size());
  for (size_t m = 0; m < out.matches.size(); ++m) {
    EXPECT_EQ(out.matches[m][0], matches[2 * m]);
    EXPECT_EQ(out.matches[m][1], matches[2 * m + 1]);
    EXPECT_NEAR(out.match_scores[m], values[m], 1e-3 * values[m]);
  }
}

TEST(LighterGlueReference, AnImageWithoutKeypointsGivesNoMatches) {
  const LighterGlueWeights w = load();
  const LighterGlueOutputs out =
      lighterglue(w, Matrix(0, 2), Matrix(0, kDescriptor), keypoints1(), descriptors1());
  EXPECT_TRUE(out.matches.empty());
  EXPECT_THROW(lighterglue(w, Matrix(3, 2), Matrix(3, 32), Matrix(3, 2), Matrix(3, 32)),
               std::invalid_argument);
}

}  // namespace
}  // namespace litgs::kernels::nn
