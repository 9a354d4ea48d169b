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

}  // namespace litgs::kernels::nn
