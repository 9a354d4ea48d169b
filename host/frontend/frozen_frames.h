// NUC-frozen frames: an uncooled thermal camera repeats its last frame while its non-uniformity correction
// runs. Such near-duplicates are detected once, here, and skipped by matching and training alike.
#pragma once

#include <vector>

namespace litgs::host::frontend {

// Feed the frames of a sequence in order, as intensities in [0, 1] (the sequence's shared stretch). A frame
// whose mean absolute difference to the previous kept (not frozen) frame is below `threshold` is frozen.
// The first frame is always kept. Frames of another size than the previous kept one are never frozen.
class FrozenFrameDetector {
 public:
  explicit FrozenFrameDetector(double threshold = 1e-4) : threshold_(threshold) {}
  bool is_frozen(const std::vector<float>& frame);  // also records the frame as kept if it is not frozen
  double threshold() const { return threshold_; }

 private:
  double threshold_;
  std::vector<float> previous_;
  bool has_previous_ = false;
};

}  // namespace litgs::host::frontend
