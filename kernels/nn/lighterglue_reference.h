// LighterGlue (XFeat's LightGlue matcher, Apache-2.0 weights in kernels/nn/models/lighterglue/) in double
// precision on the CPU, as its exported graph computes it: the reference the device matcher is tested
// against, itself tested against onnxruntime's outputs (tests/data/lighterglue/).
#pragma once

#include <array>
#include <vector>

#include "kernels/nn/attention_reference.h"
#include "kernels/nn/nn_weights.h"

namespace litgs::kernels::nn {

struct LighterGlueOutputs {
  Matrix scores;  // [n0][n1]: the log assignment (dual log-softmax plus both log matchabilities)
  // Mutual best pairs (each the other's highest score), in order of the first index, with exp(score); the
  // graph keeps them all: a caller keeps those above its threshold (XFeat's min_conf, 0.1).
  std::vector<std::array<int, 2>> matches;
  std::vector<double> match_scores;
};

// LighterGlue's keypoint normalization: (p - size / 2) / (max(width, height) / 2).
Matrix normalize_keypoints(const std::vector<float>& xy, int width, int height);

// keypoints: [n][2] normalized (normalize_keypoints); descriptors: [n][64]. std::invalid_argument on other
// shapes; an image without keypoints gives no scores and no matches.
LighterGlueOutputs lighterglue(const LighterGlueWeights& w, const Matrix& keypoints0,
                               const Matrix& descriptors0, const Matrix& keypoints1,
                               const Matrix& descriptors1);

// The mutual best pairs of a score matrix (ties: the lowest index, as ONNX TopK), with exp(score).
void mutual_best(const Matrix& scores, std::vector<std::array<int, 2>>& matches, std::vector<double>& values);

}  // namespace litgs::kernels::nn
