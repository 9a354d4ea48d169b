// XFeat's post-processing on the device (nn_keypoints.comp): the keypoint heat map, NMS scores times
// reliability, channel normalization and descriptors at keypoints. Its CPU double reference is
// kernels/nn/xfeat_keypoints_reference.h, op for op.
#pragma once

#include <cstdint>
#include <memory>

#include "engine/buffer.h"
#include "engine/context.h"
#include "engine/kernel.h"
#include "engine/sequence.h"
#include "kernels/nn/nn_conv.h"

namespace litgs::kernels {

class KeypointKernel {
 public:
  explicit KeypointKernel(engine::Context& context);
  ~KeypointKernel();
  // heat [8h][8w] from logits [65][h][w].
  void heatmap(engine::Sequence& s, const engine::Buffer& logits, const engine::Buffer& heat, uint32_t h,
               uint32_t w) const;
  // scores [8h][8w] from heat [8h][8w] and reliability [h][w].
  void scores(engine::Sequence& s, const engine::Buffer& heat, const engine::Buffer& reliability,
              const engine::Buffer& scores, uint32_t h, uint32_t w, float threshold, uint32_t window) const;
  // out [C][h][w]: features divided by their norm over the channels.
  void normalize(engine::Sequence& s, const engine::Buffer& features, const engine::Buffer& out,
                 const MapShape& shape) const;
  // descriptors [count][C] at `count` (x, y) pairs of an 8h x 8w image; C at most 64.
  void descriptors(engine::Sequence& s, const engine::Buffer& normalized, const engine::Buffer& xy,
                   const engine::Buffer& out, const MapShape& shape, uint32_t count) const;

 private:
  engine::Context* context_;
  std::unique_ptr<engine::Kernel> kernel_;
};

}  // namespace litgs::kernels
