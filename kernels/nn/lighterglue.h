// LighterGlue on the device: the matcher of kernels/nn/lighterglue_reference.h run with the operations of
// attention.h, both images' keypoints stacked in one set of buffers. The score matrix is computed on the
// device; the mutual best pairs are chosen on the host from it (as XFeat's top-k), deterministically.
#pragma once

#include <array>
#include <memory>
#include <vector>

#include "engine/buffer.h"
#include "engine/context.h"
#include "engine/sequence.h"
#include "kernels/nn/attention.h"
#include "kernels/nn/nn_weights.h"

namespace litgs::kernels {

struct LighterGlueMatches {
  std::vector<float> scores;                     // [n0][n1]: the log assignment
  std::vector<std::array<int, 2>> matches;       // mutual best pairs, in order of the first index
  std::vector<double> match_scores;              // exp(score) of each: a caller keeps those above a threshold
  std::vector<engine::KernelTime> kernel_times;  // device time per kernel (none without timestamps)
};

class LighterGlueNetwork {
 public:
  // std::invalid_argument when the weights do not have LighterGlue's shapes.
  LighterGlueNetwork(engine::Context& context, const nn::LighterGlueWeights& weights);
  ~LighterGlueNetwork();
  // keypoints: [n][2] normalized (nn::normalize_keypoints); descriptors: [n][descriptor width]. An image
  // without keypoints gives no matches; other sizes are std::invalid_argument.
  LighterGlueMatches match(const std::vector<float>& keypoints0, const std::vector<float>& descriptors0,
                           const std::vector<float>& keypoints1,
                           const std::vector<float>& descriptors1) const;
  uint32_t descriptor_width() const { return descriptor_width_; }

 private:
  struct Linear {
    std::unique_ptr<engine::DeviceArray<float>> weight, bias;
    uint32_t in = 0, out = 0;
  };
  struct FeedForward {
    Linear expand, project;
    std::unique_ptr<engine::DeviceArray<float>> scale, shift;
    float epsilon = 1e-5f;
  };
  struct Layer {
    Linear qkv, self_out, cross_qk, cross_v, cross_out;
    FeedForward self_ffn, cross_ffn;
  };
  Linear upload(const nn::LinearWeights& w, const char* name);
  FeedForward upload(const nn::FeedForwardWeights& f);

  engine::Context* context_;
  AttentionKernels ops_;
  uint32_t descriptor_width_ = 0, dim_ = 0;
  Linear input_, final_, matchability_;
  std::unique_ptr<engine::DeviceArray<float>> rotary_;
  std::vector<Layer> layers_;
};

}  // namespace litgs::kernels
