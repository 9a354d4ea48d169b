#include "kernels/nn/xfeat_reference.h"

#include <stdexcept>
#include <string>
#include <utility>

namespace litgs::kernels::nn {
XfeatReference::XfeatReference(XfeatWeights weights) : weights_(std::move(weights)) {
  if (weights_.convs.size() != 27)
    throw std::invalid_argument("XfeatReference: " + std::to_string(weights_.convs.size()) +
                                " convolutions, XFeat has 27");
}

FeatureMap XfeatReference::apply(const FeatureMap& in, size_t first, size_t count, bool relu_last) const {
  FeatureMap x = in;
  for (size_t i = first; i < first + count; ++i) {
    x = conv2d(x, weights_.convs[i]);
    if (i + 1 < first + count || relu_last) relu(x);
  }
  return x;
}

XfeatOutputs XfeatReference::run(const FeatureMap& image) const {
  if (image.channels != 1 || image.height <= 0 || image.width <= 0 || image.height % 32 || image.width % 32)
    throw std::invalid_argument("XFeat: a one-channel image whose sides are positive multiples of 32, not " +
                                std::to_string(image.width) + "x" + std::to_string(image.height));
  // Convolution indices of each module, in XfeatWeights order.
  const FeatureMap x1 = apply(image, 0, 4, true);
  const FeatureMap skip = apply(average_pool(image, 4, 4), 4, 1, false);
  const FeatureMap x2 = apply(add(x1, skip), 5, 2, true);
  const FeatureMap x3 = apply(x2, 7, 3, true);
  const FeatureMap x4 = apply(x3, 10, 3, true);
  const FeatureMap x5 = apply(x4, 13, 4, true);
  const FeatureMap fused =
      add(add(x3, resize_bilinear(x4, x3.height, x3.width)), resize_bilinear(x5, x3.height, x3.width));
  XfeatOutputs out;
  out.features = apply(fused, 17, 3, false);
  out.heatmap = apply(out.features, 20, 3, false);
  sigmoid(out.heatmap);
  out.keypoints = apply(unfold(image, 8), 23, 4, false);
  return out;
}

}  // namespace litgs::kernels::nn
