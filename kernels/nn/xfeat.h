// XFeat's network on the Vulkan device (nn_conv2d.comp and nn_map.comp), the same dataflow as
// kernels/nn/xfeat_reference.h, its CPU double reference. Weights are uploaded once; intermediate maps are
// allocated for the size of each call. The post-processing (softmax, NMS, top-k, descriptor sampling) and the
// matchers are not here yet (issue 47).
#pragma once

#include <memory>
#include <vector>

#include "engine/buffer.h"
#include "engine/context.h"
#include "kernels/nn/nn_conv.h"
#include "kernels/nn/nn_weights.h"

namespace litgs::kernels {

struct XfeatDeviceOutputs {
  uint32_t height = 0, width = 0;  // of the maps: the image's / 8
  std::vector<float> features;     // [64][height][width], not L2-normalized
  std::vector<float> keypoints;    // [65][height][width] logits
  std::vector<float> heatmap;      // [height][width] reliability
};

class XfeatNetwork {
 public:
  // Uploads the weights (host/nn/xfeat_weights.h reads them); std::invalid_argument unless there are 27.
  XfeatNetwork(engine::Context& context, const nn::XfeatWeights& weights);
  ~XfeatNetwork();
  // `image`: height x width values, normalized to zero mean and unit variance; the sides positive multiples
  // of 32 (std::invalid_argument otherwise). Records, submits and waits.
  XfeatDeviceOutputs run(const std::vector<float>& image, uint32_t height, uint32_t width) const;

 private:
  struct Layer {
    std::unique_ptr<engine::DeviceArray<float>> weight, bias;
    uint32_t in_channels, out_channels, kernel, stride, pad;
  };
  engine::Context* context_;
  std::vector<Layer> layers_;
  Conv2dKernel conv_;
  MapKernel map_;
};

}  // namespace litgs::kernels
