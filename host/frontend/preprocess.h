// Thermal frames to the 8-bit images features are detected on: the sequence's percentile stretch (16-bit
// frames; optionally per sliding window), CLAHE, and the NUC-frozen frames found once.
#pragma once

#include <cstddef>
#include <cstdint>
#include <filesystem>
#include <vector>

#include "host/frontend/intensity.h"
#include "io/scene.h"

namespace litgs::host::frontend {

struct PreprocessOptions {
  double low_percentile = 0.5, high_percentile = 99.5;  // of the 16-bit counts (8-bit frames: as they are)
  size_t stretch_window = 0;  // 0: one stretch for the sequence; N: over the N frames around each frame
  bool clahe = true;
  double clahe_clip_limit = 2.0;   // OpenCV's clip limit (contrast limiting per tile)
  int clahe_tiles = 8;             // tile grid clahe_tiles x clahe_tiles
  double frozen_threshold = 1e-4;  // mean |difference| in the sequence stretch's [0, 1] (FrozenFrameDetector)
  void check() const;              // std::invalid_argument naming the field
};

struct Gray8 {
  int width = 0, height = 0;
  std::vector<uint8_t> pixels;  // row-major
};

struct PreprocessedFrame {
  Gray8 image;           // empty for frozen frames
  Stretch stretch;       // raw -> [0, 1] used for this frame
  bool frozen = false;   // a near-duplicate of the previous kept frame
  bool uniform = false;  // no contrast at all after the stretch (every pixel the same)
};

// Loads every frame of `scene` (read from `dir`) and preprocesses it. IoError from the readers (a frame of
// the wrong size names the file).
std::vector<PreprocessedFrame> preprocess_frames(const std::filesystem::path& dir, const io::Scene& scene,
                                                 const PreprocessOptions& options);

// An 8-bit image resized bilinearly with half-pixel centres (OpenCV's INTER_LINEAR, PyTorch's bilinear
// without corner alignment), for a network that takes sides of given multiples.
Gray8 resize_gray8(const Gray8& image, int width, int height);

// One raw single-channel image to 8 bits with `stretch`, then CLAHE if asked (exposed for tests).
Gray8 to_gray8(const io::Image& raw, const Stretch& stretch, const PreprocessOptions& options);

}  // namespace litgs::host::frontend
