// How matchable a scene's thermal frames are, measured the same way for any two scenes so that synthetic
// frames can be calibrated against real ones (`litgs-engine compare-frames`, docs/synthetic-appearance.md):
// the distribution of gradient magnitudes of the stretched 8-bit frames (before CLAHE), and what the front
// end makes of them (keypoints per image, inlier ratio, matches lost to track conflicts).
#pragma once

#include <filesystem>
#include <string>
#include <vector>

#include "host/frontend/frontend.h"

namespace litgs::host::frontend {

// Histogram of the Sobel gradient magnitude (grey levels per pixel, Sobel divided by 8), bins of one grey
// level from 0 to kGradientBins - 1, the last bin holding everything above. Normalized to sum 1.
inline constexpr int kGradientBins = 64;
struct GradientHistogram {
  std::vector<double> share = std::vector<double>(kGradientBins, 0.0);
  double median = 0, p90 = 0;  // grey levels per pixel
  size_t pixels = 0;
};

// Over all the frames given (interior pixels only). Empty frames are skipped.
GradientHistogram gradient_histogram(const std::vector<Gray8>& frames);

// The 1-D earth mover's distance between two histograms, in grey levels per pixel: how far the gradient
// magnitudes of one set must move to match the other's.
double histogram_distance(const GradientHistogram& a, const GradientHistogram& b);

struct SceneAppearance {
  GradientHistogram gradients;  // of the frames stretched as the front end stretches them, without CLAHE
  FrontendSummary frontend;     // the front end with the given options
  int width = 0, height = 0;
};

// Reads and measures the scene at `dir` (nothing is written). The front end runs with `options`.
SceneAppearance measure_appearance(const std::filesystem::path& dir, const FrontendOptions& options);

// The comparison as text: one row per measure (reference, scene, scene / reference) and the histogram
// distance; a note where the two differ in size.
std::string compare_appearance_text(const SceneAppearance& reference, const SceneAppearance& scene);
// The same as a JSON object's text.
std::string compare_appearance_json(const SceneAppearance& reference, const SceneAppearance& scene);

}  // namespace litgs::host::frontend
