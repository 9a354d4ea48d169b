#include "host/frontend/frozen_frames.h"

#include <cmath>

namespace litgs::host::frontend {

bool FrozenFrameDetector::is_frozen(const std::vector<float>& frame) {
  if (has_previous_ && previous_.size() == frame.size() && !frame.empty()) {
    double diff = 0;
    for (size_t p = 0; p < frame.size(); ++p) diff += std::abs(frame[p] - previous_[p]);
    if (diff / static_cast<double>(frame.size()) < threshold_) return true;
  }
  previous_ = frame;
  has_previous_ = true;
  return false;
}

}  // namespace litgs::host::frontend
