// XFeat's network (Potje et al., CVPR 2024) in double precision on the CPU, with the weights, strides and
// paddings of kernels/nn/models/xfeat/xfeat_640x640.onnx: the reference the device implementation is tested
// against, itself tested against onnxruntime's outputs (tests/data/xfeat/). Any image whose sides are
// multiples of 32 (the ONNX graph's glue fixes 640x640; the convolutions do not).
#pragma once

#include <vector>

#include "io/onnx_model.h"
#include "kernels/nn/nn_reference.h"

namespace litgs::kernels::nn {

struct XfeatOutputs {
  FeatureMap features;   // 64 x H/8 x W/8, not L2-normalized
  FeatureMap keypoints;  // 65 x H/8 x W/8 logits: the 8x8 cell positions and "no keypoint"
  FeatureMap heatmap;    // 1 x H/8 x W/8 reliability, after the sigmoid
};

class XfeatReference {
 public:
  // Keeps the model and takes its 27 convolutions from the model in graph order and checks that they are
  // XFeat's (their names, shapes and count); io::IoError naming the model file otherwise.
  explicit XfeatReference(io::OnnxModel model);
  // `image`: one channel, normalized to zero mean and unit variance; std::invalid_argument when its sides
  // are not positive multiples of 32.
  XfeatOutputs run(const FeatureMap& image) const;

 private:
  struct Conv {
    const io::OnnxTensor* weight;
    const io::OnnxTensor* bias;
    int stride, pad;
  };
  FeatureMap apply(const FeatureMap& in, size_t first, size_t count, bool relu_last) const;
  io::OnnxModel model_;  // owns the weights convs_ points into
  std::vector<Conv> convs_;
};

}  // namespace litgs::kernels::nn
