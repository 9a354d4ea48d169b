// Double-precision CPU references of the network operations the learned front end runs (issue 47): the
// baseline each compute shader in kernels/nn/ is tested against, itself tested against an independent
// runtime through the whole network (xfeat_reference.h). Feature maps are one image's channels x rows x
// columns, row-major.
#pragma once

#include <cstddef>
#include <vector>

#include "kernels/nn/nn_weights.h"

namespace litgs::kernels::nn {

struct FeatureMap {
  int channels = 0, height = 0, width = 0;
  std::vector<double> values;  // [channel][row][column]
  FeatureMap() = default;
  FeatureMap(int c, int h, int w) : channels(c), height(h), width(w), values(size_t(c) * h * w, 0.0) {}
  double& at(int c, int y, int x) { return values[(size_t(c) * height + y) * width + x]; }
  double at(int c, int y, int x) const { return values[(size_t(c) * height + y) * width + x]; }
};

// ONNX Conv, group 1, dilation 1, with w's stride and zero padding on every side.
FeatureMap conv2d(const FeatureMap& in, const ConvWeights& w);
void relu(FeatureMap& m);
void sigmoid(FeatureMap& m);
// a + b, of one shape (std::invalid_argument otherwise).
FeatureMap add(const FeatureMap& a, const FeatureMap& b);
// ONNX AveragePool without padding: a k x k window every `stride` pixels.
FeatureMap average_pool(const FeatureMap& in, int k, int stride);
// ONNX Resize, mode linear, coordinate_transformation_mode half_pixel (PyTorch's bilinear with
// align_corners false): source coordinate (d + 0.5) * in / out - 0.5, clamped to the image.
FeatureMap resize_bilinear(const FeatureMap& in, int height, int width);
// XFeat's _unfold2d of a one-channel image: each ws x ws block becomes ws * ws channels, channel
// ky * ws + kx holding the block's pixel (ky, kx).
FeatureMap unfold(const FeatureMap& in, int ws);

}  // namespace litgs::kernels::nn
