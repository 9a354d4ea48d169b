// Co-visibility of held-out pixels, from true depth: a pixel of a held-out view counts when at least one
// training view sees the same surface point (DyCheck's co-visibility mask, Gao et al. 2022). A held-out view
// at the end of a trajectory shows surfaces no training view saw; what a model renders there is
// extrapolation, and the masked PSNR leaves it out so that models are compared on what the data constrains.
// The mask depends only on the true depth and poses, never on the model being evaluated.
#pragma once

#include <cstdint>
#include <filesystem>
#include <span>
#include <string>
#include <vector>

#include "host/train/training_data.h"
#include "kernels/splat/splat_types.h"

namespace litgs::host {

// A view's true depth: z along the camera's axis (metres) per pixel of camera's resolution, row-major; 0
// where the ray meets no surface (sky) within the depth image's range.
struct DepthView {
  kernels::SplatCamera camera;  // pinhole, its pose the true one
  std::vector<float> depth_m;   // [height][width]
};

struct CovisibilityOptions {
  // A training view sees the point when its own true depth at the point's projection (any of the four
  // pixels around it: lenient at depth edges) agrees with the point's depth in that view within
  // max(min_tolerance_m, relative_tolerance * depth).
  double relative_tolerance = 0.01;
  double min_tolerance_m = 0.02;
};

// 1 per pixel of `target` that some view of `others` sees, else 0. A sky pixel (depth 0) counts when a view
// looks in that direction and sees sky there too.
std::vector<uint8_t> covisible_pixels(const DepthView& target, const std::vector<DepthView>& others,
                                      const CovisibilityOptions& options = {});

// A mask at (width, height) to one at (out_width, out_height) (training's downscale): an output pixel is
// covisible when at least half of the input pixels whose centres fall inside it are.
std::vector<uint8_t> downscale_mask(const std::vector<uint8_t>& mask, uint32_t width, uint32_t height,
                                    uint32_t out_width, uint32_t out_height);

// PSNR (peak 1) over the pixels where mask is 1; NaN when none is.
double masked_psnr(std::span<const float> image, std::span<const float> target,
                   const std::vector<uint8_t>& mask);

// The masks of data's held-out views at the training resolution, each against all of its training views,
// from the scene's true depth (gt/depth/<frame name>, 16-bit millimetres as `litgs-engine synth` writes it)
// and true poses (gt/poses.txt). Where the scene lacks them, a file is unreadable or of the wrong size, or
// the camera is not an undistorted pinhole, `masks` is empty and `unavailable` says why.
struct HeldoutCovisibility {
  std::vector<std::vector<uint8_t>> masks;  // [view of data]: empty for training views
  std::string unavailable;
};
HeldoutCovisibility heldout_covisibility(const std::filesystem::path& scene_dir, const io::Scene& scene,
                                         const TrainingData& data, const CovisibilityOptions& options = {});

}  // namespace litgs::host
