// A network's convolution weights as the kernels and their references take them: plain arrays, no file
// format (host/nn/ reads them from the ONNX models).
#pragma once

#include <cstdint>
#include <vector>

namespace litgs::kernels::nn {

struct ConvWeights {
  uint32_t out_channels = 0, in_channels = 0, kernel = 0;
  std::vector<float> weight;  // [out][in][kernel][kernel]
  std::vector<float> bias;    // [out]
  uint32_t stride = 1, pad = 0;
};

// XFeat's 27 convolutions in the order the network applies them: block1 (4), skip1 (1), block2 (2), block3
// (3), block4 (3), block5 (4), block_fusion (3), heatmap_head (3), keypoint_head (4).
struct XfeatWeights {
  std::vector<ConvWeights> convs;
};

// ONNX MatMul by a weight, then Add of a bias: y[out] = sum_i x[i] weight[i][out] + bias[out].
struct LinearWeights {
  uint32_t in = 0, out = 0;
  std::vector<float> weight;  // [in][out] (the MatMul's right operand)
  std::vector<float> bias;    // [out]; empty: none
};

// ONNX LayerNormalization over the last axis.
struct LayerNormWeights {
  std::vector<float> scale, bias;
  double epsilon = 1e-5;
};

// LightGlue's feed-forward update of a keypoint from [itself, its message]: expand, layer norm, GELU (the
// exact one, with erf), project.
struct FeedForwardWeights {
  LinearWeights expand;  // 2 dim -> 2 dim
  LayerNormWeights norm;
  LinearWeights project;  // 2 dim -> dim
};

// LighterGlue (XFeat's LightGlue, one head), layer by layer: self-attention with rotary positional
// encoding, then cross-attention, each followed by its feed-forward update; then the assignment's head.
struct LighterGlueWeights {
  LinearWeights input_projection;  // descriptor (64) -> dim (96)
  std::vector<float> position;     // [2][dim / 2]: keypoint (x, y) -> rotary frequencies (no bias)
  struct Layer {
    LinearWeights qkv;  // dim -> 3 dim, interleaved: channel 3 d + {0, 1, 2} is q, k, v's d
    LinearWeights self_out;
    FeedForwardWeights self_ffn;
    LinearWeights cross_qk, cross_v, cross_out;
    FeedForwardWeights cross_ffn;
  };
  std::vector<Layer> layers;
  LinearWeights final_projection;  // dim -> dim
  LinearWeights matchability;      // dim -> 1
  uint32_t dim() const { return input_projection.out; }
};

}  // namespace litgs::kernels::nn
