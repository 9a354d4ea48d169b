// XFeat's network on the Vulkan device (nn_conv2d.comp and nn_map.comp), the same dataflow as
// kernels/nn/xfeat_reference.h, its CPU double reference, and its post-processing (nn_keypoints.comp, as
// kernels/nn/xfeat_keypoints_reference.h): keypoints and descriptors. Weights are uploaded once; intermediate
// maps are allocated for the size of each call.
#pragma once

#include <functional>
#include <memory>
#include <vector>

#include "engine/buffer.h"
#include "engine/context.h"
#include "engine/sequence.h"
#include "kernels/nn/nn_conv.h"
#include "kernels/nn/nn_keypoints.h"
#include "kernels/nn/nn_weights.h"
#include "kernels/nn/xfeat_keypoints_reference.h"

namespace litgs::kernels {

struct XfeatDeviceOutputs {
  uint32_t height = 0, width = 0;                // of the maps: the image's / 8
  std::vector<float> features;                   // [64][height][width], not L2-normalized
  std::vector<float> keypoints;                  // [65][height][width] logits
  std::vector<float> heatmap;                    // [height][width] reliability
  std::vector<engine::KernelTime> kernel_times;  // device time per kernel (none without timestamps)
};

struct XfeatDetections {
  uint32_t height = 0, width = 0;             // of the image
  std::vector<nn::ScoredKeypoint> keypoints;  // highest score first (or in the selection's order)
  std::vector<float> descriptors;             // keypoints.size() x 64, L2-normalized
};

class XfeatNetwork {
 public:
  // Uploads the weights (host/nn/xfeat_weights.h reads them); std::invalid_argument unless there are 27.
  XfeatNetwork(engine::Context& context, const nn::XfeatWeights& weights);
  ~XfeatNetwork();
  // `image`: height x width values, normalized to zero mean and unit variance; the sides positive multiples
  // of 32 (std::invalid_argument otherwise). Records, submits and waits.
  XfeatDeviceOutputs run(const std::vector<float>& image, uint32_t height, uint32_t width) const;
  // Which of the top-k keypoints (highest score first) to describe, as indices into them; describes all
  // when empty. The front end's grid bucketing keeps a share of the candidates, and only those need the
  // descriptors' bicubic sampling.
  using KeypointSelection = std::function<std::vector<size_t>(const std::vector<nn::ScoredKeypoint>&)>;

  // The network and the post-processing: on the device but for the top-k choice, which reads back the
  // score map. The detections hold the selected keypoints in the selection's order, with their descriptors.
  // Deterministic: one image gives the same keypoints and descriptors on one device.
  XfeatDetections detect(const std::vector<float>& image, uint32_t height, uint32_t width,
                         const nn::XfeatKeypointOptions& options = {},
                         const KeypointSelection& select = {}) const;

 private:
  struct Pass;
  // Records the forward pass into pass's sequence; its maps live in the pass.
  void forward(Pass& pass, const std::vector<float>& image, uint32_t height, uint32_t width) const;
  struct Layer {
    std::unique_ptr<engine::DeviceArray<float>> weight, bias;
    uint32_t in_channels, out_channels, kernel, stride, pad;
  };
  engine::Context* context_;
  std::vector<Layer> layers_;
  Conv2dKernel conv_;
  MapKernel map_;
  KeypointKernel keypoints_;
};

}  // namespace litgs::kernels
