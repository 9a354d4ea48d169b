// XFeat's network (Potje et al., CVPR 2024) in double precision on the CPU, with the weights, strides and
// paddings of kernels/nn/models/xfeat/xfeat_640x640.onnx (read by host/nn/xfeat_weights.h): the reference the
// device network (xfeat.h) is tested against, itself tested against onnxruntime's outputs
// (tests/data/xfeat/). Any image whose sides are multiples of 32 (the ONNX graph's glue fixes 640x640; the
// convolutions do not).
#pragma once

#include <vector>

#include "kernels/nn/nn_reference.h"
#include "kernels/nn/nn_weights.h"

namespace litgs::kernels::nn {

struct XfeatOutputs {
  FeatureMap features;   // 64 x H/8 x W/8, not L2-normalized
  FeatureMap keypoints;  // 65 x H/8 x W/8 logits: the 8x8 cell positions and "no keypoint"
  FeatureMap heatmap;    // 1 x H/8 x W/8 reliability, after the sigmoid
};

class XfeatReference {
 public:
  // std::invalid_argument when there are not 27 convolutions.
  explicit XfeatReference(XfeatWeights weights);
  // `image`: one channel, normalized to zero mean and unit variance; std::invalid_argument when its sides
  // are not positive multiples of 32.
  XfeatOutputs run(const FeatureMap& image) const;

 private:
  FeatureMap apply(const FeatureMap& in, size_t first, size_t count, bool relu_last) const;
  XfeatWeights weights_;
};

}  // namespace litgs::kernels::nn
