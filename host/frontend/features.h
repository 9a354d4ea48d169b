// Keypoints and descriptors (ORB, SIFT or AKAZE through OpenCV; XFeat on the Vulkan device through a
// LearnedDetector, host/nn/xfeat_features.h) with a per-image budget spread over the image by grid
// bucketing, so that low-texture thermal frames still get keypoints everywhere.
#pragma once

#include <cstdint>
#include <functional>
#include <string>
#include <vector>

#include "host/frontend/preprocess.h"
#include "io/sfm_files.h"

namespace litgs::host::frontend {

enum class FeatureType { kOrb, kSift, kAkaze, kXfeat };
std::string feature_name(FeatureType type);
FeatureType parse_feature_type(
    const std::string& name);  // "orb" | "sift" | "akaze" | "xfeat"; invalid_argument

struct FeatureOptions {
  FeatureType type = FeatureType::kSift;
  int max_keypoints = 3000;  // per image
  // Grid bucketing: each of grid_cols x grid_rows cells keeps its strongest max_keypoints / cells first, the
  // rest of the budget goes to the strongest left anywhere. 0 cells: strongest overall.
  int grid_cols = 8, grid_rows = 8;
  // The classical detectors: a keypoint nearer than this to a stronger one is dropped before bucketing (0:
  // none). A blurred feature found at two scales a pixel or two apart otherwise gives two keypoints whose
  // matches put both in one track, a conflict that costs one of them.
  double min_spacing_px = 0;
  // XFeat: the frame is resized by this factor before the network. Its keypoints lie on whole pixels of the
  // network's input and its descriptors on cells of 8 of them, so a larger input places both more finely
  // in the frame (at the square of the factor in device time).
  double xfeat_scale = 1;
  void check() const;  // std::invalid_argument naming the field
};

struct ImageFeatures {
  std::vector<io::SfmKeypoint> keypoints;
  std::vector<uint8_t> descriptors;  // keypoints.size() rows of descriptor_bytes
  int descriptor_bytes = 0;
  bool float_descriptors = false;  // rows of float (SIFT) or bit strings (ORB, AKAZE)
};

// Detects and describes; an empty or uniform image gives no keypoints (not an error). kXfeat runs on the
// device, which this library does not reach: std::invalid_argument (use a LearnedDetector).
ImageFeatures detect_features(const Gray8& image, const FeatureOptions& options);

// A detector that runs outside this library (a network on the Vulkan device), called once per kept frame,
// possibly from several threads at once.
using LearnedDetector = std::function<ImageFeatures(const Gray8&)>;

// Indices of the keypoints at (x, y) that no stronger one lies within `min_spacing` pixels of (ties: the
// lower index is the stronger); keypoints at one position (SIFT's orientations of one feature) are all
// kept, as they are one feature. Sorted.
std::vector<size_t> spaced_keypoints(const std::vector<float>& x, const std::vector<float>& y,
                                     const std::vector<float>& response, double min_spacing);

// Indices of at most `budget` of the keypoints at (x, y) with `response`: per cell of the grid the
// strongest budget / cells first, then the strongest of the rest. Ties keep the lower index. Sorted.
std::vector<size_t> bucket_keypoints(const std::vector<float>& x, const std::vector<float>& y,
                                     const std::vector<float>& response, int width, int height, int budget,
                                     int grid_cols, int grid_rows);

}  // namespace litgs::host::frontend
