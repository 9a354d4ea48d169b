// XFeat's post-processing (Potje et al., CVPR 2024, `detectAndCompute`) in double precision on the CPU:
// keypoints and descriptors from the network's outputs (xfeat_reference.h). The reference the device's
// post-processing (nn_keypoints.comp, xfeat.h) is tested against, step by step.
//
// Positions are full-resolution pixels (x right, y down, pixel centres at integers). The 1/8-resolution maps
// are sampled at a full-resolution position as XFeat samples them (grid_sample without corner alignment
// after scaling x by 1 / (W - 1)): map coordinate x * w / (W - 1) - 0.5, zero outside the map.
#pragma once

#include <cstdint>
#include <vector>

#include "kernels/nn/nn_reference.h"

namespace litgs::kernels::nn {

struct XfeatKeypointOptions {
  uint32_t top_k = 4096;    // keypoints kept, by score
  double threshold = 0.05;  // a keypoint's heat must exceed this
  int nms_window = 5;       // a keypoint is the largest heat of this window around it
};

// Softmax over the 65 bins of each cell, the 64 position bins laid out as the cell's 8 x 8 pixels
// (bin ky * 8 + kx at row 8 cy + ky, column 8 cx + kx): 1 x 8h x 8w.
FeatureMap keypoint_heatmap(const FeatureMap& logits);

// Per pixel: its heat times the reliability (bilinear at the pixel) where its heat exceeds the threshold
// and is the largest of the window around it (ties all kept), else 0. 1 x H x W.
FeatureMap keypoint_scores(const FeatureMap& heatmap, const FeatureMap& reliability,
                           const XfeatKeypointOptions& options);

struct ScoredKeypoint {
  float x = 0, y = 0, score = 0;
};

// At most top_k of the pixels with a positive score, the highest first (ties: row-major order). Shared by
// the reference and the device path, which downloads its score map.
std::vector<ScoredKeypoint> top_keypoints(const std::vector<float>& scores, int width, int height,
                                          uint32_t top_k);

// Each cell's 64 channels divided by their L2 norm (at least 1e-12).
FeatureMap normalize_channels(const FeatureMap& features);

// value of a 1/8-resolution map's channel at a full-resolution position (width x height image), bilinear.
double sample_bilinear(const FeatureMap& map, int channel, double x, double y, int width, int height);

// The descriptors at the keypoints: bicubic (a = -0.75, as grid_sample) in the normalized features, then
// L2-normalized. keypoints.size() rows of features.channels values.
std::vector<double> sample_descriptors(const FeatureMap& normalized,
                                       const std::vector<ScoredKeypoint>& keypoints, int width, int height);

struct XfeatKeypoints {
  std::vector<ScoredKeypoint> keypoints;
  std::vector<double> descriptors;  // keypoints.size() x 64
};

// The whole post-processing: features 64 x h x w, logits 65 x h x w, reliability 1 x h x w of an image of
// 8w x 8h pixels.
XfeatKeypoints detect_keypoints(const FeatureMap& features, const FeatureMap& logits,
                                const FeatureMap& reliability, const XfeatKeypointOptions& options);

}  // namespace litgs::kernels::nn
