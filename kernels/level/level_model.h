// The radiometric level model on the device (level_shared.h): per frame a log-gain and an offset, and
// optionally a vignetting shared by all frames, applied to the rendered image before the photometric loss
// and learned with it by Adam, with regularizers toward identity and toward smoothness in time.
// The CPU double reference of the same math is kernels/level/level_reference.h.
#pragma once

#include <cstdint>
#include <memory>
#include <vector>

#include "engine/buffer.h"
#include "engine/context.h"
#include "engine/kernel.h"
#include "engine/sequence.h"
#include "kernels/level/level_shared.h"

namespace litgs::kernels {

// The image the level applies to: [channels][height][width] floats, the camera's principal point.
struct LevelGeometry {
  uint32_t width = 0, height = 0, channels = 1;
  float cx = 0, cy = 0;
  LevelParams params(uint32_t frame, uint32_t frames, bool vignetting) const;
};

// One optimizer step of the level parameters for the frame whose image was rendered.
struct LevelStep {
  uint32_t frame = 0;
  int prev = -1, next = -1;  // the frame's neighbours in time for the smoothness term (-1: none)
  bool center = true;        // re-centre the trained frames on their mean (the map's level, level_shared.h)
  float lr_log_gain = 0, lr_offset = 0, lr_vignetting = 0;
  float lambda_identity = 0, lambda_smooth = 0;
  float beta1 = 0.9f, beta2 = 0.999f, eps = 1e-8f;
};

class LevelModel {
 public:
  // One row per frame at identity, `trained[f]` marking the frames that are trained (the others, held out,
  // stay at identity and out of the mean); `vignetting`: learn the shared vignetting too (else v = 1).
  LevelModel(engine::Context& context, const std::vector<bool>& trained, bool vignetting);
  ~LevelModel();

  uint32_t frames() const { return frames_; }
  bool vignetting() const { return vignetting_; }
  // Allocates the scratch for images of `elements` values (C * H * W) now (the records grow it otherwise).
  void reserve(uint64_t elements);

  // Records leveled() = g v image + o for `frame` (no submit).
  void record_apply(engine::Sequence& sequence, const engine::Buffer& image, uint32_t frame,
                    const LevelGeometry& geometry);
  // Records the backward and the step: reads grad_leveled() (dL/dx', written by the loss), OVERWRITES
  // grad_image with dL/dx, and updates step.frame's row and the vignetting. Call after record_apply() with
  // the same image, frame and geometry, before another record_apply().
  void record_backward_step(engine::Sequence& sequence, const engine::Buffer& image,
                            const LevelGeometry& geometry, const LevelStep& step,
                            const engine::Buffer& grad_image);

  const engine::Buffer& leveled() const { return leveled_->buffer(); }
  const engine::Buffer& grad_leveled() const { return grad_leveled_->buffer(); }

  // The identity state of `trained.size()` frames.
  static std::vector<float> identity_state(const std::vector<bool>& trained);
  // The state, [frames + 1][LEVEL_STRIDE] (level_shared.h): for checkpoints, evaluation and tests.
  std::vector<float> download_state() const;
  // Throws std::invalid_argument when `state` does not hold (frames + 1) * LEVEL_STRIDE values.
  void upload_state(const std::vector<float>& state);

 private:
  engine::Context* context_;
  uint32_t frames_;
  bool vignetting_;
  std::unique_ptr<engine::Kernel> apply_, backward_, step_;
  engine::DeviceArray<float> state_;
  std::unique_ptr<engine::DeviceArray<float>> leveled_, grad_leveled_, block_sums_;
};

// Gain, offset and vignetting of a frame row of a state ([frames + 1][LEVEL_STRIDE]).
struct LevelValues {
  double log_gain = 0, offset = 0, k1 = 0, k2 = 0;
};
LevelValues level_values(const std::vector<float>& state, uint32_t frame, bool vignetting);

}  // namespace litgs::kernels
