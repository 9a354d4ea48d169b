// Which image pairs to match: a sequential window, covisibility from the prior poses, or every pair.
#pragma once

#include <Eigen/Core>
#include <array>
#include <cstdint>
#include <string>
#include <vector>

namespace litgs::host::frontend {

enum class PairMode { kCovisible, kSequential, kExhaustive };

struct PairOptions {
  PairMode mode = PairMode::kCovisible;
  size_t window = 3;  // sequential: each image with the next `window`; covisible: its first pass
  // Covisible: the view axes within this angle, and on average over both directions at least this fraction
  // of a grid of pixels, put at the image's scene depth, seen by the other view.
  double max_axis_angle_deg = 75;
  double min_overlap = 0.2;
  void check() const;  // std::invalid_argument
};

// "covisible", "covisible:N" (first-pass window N), "sequential:N", "exhaustive"; invalid_argument.
PairOptions parse_pairs(const std::string& text);
std::string pairs_name(const PairOptions& options);

using ImagePair = std::array<uint32_t, 2>;  // first < second

// Pairs among `images` (increasing indices; frozen frames already left out).
std::vector<ImagePair> sequential_pairs(const std::vector<uint32_t>& images, size_t window);
std::vector<ImagePair> exhaustive_pairs(const std::vector<uint32_t>& images);

struct PairView {
  bool valid = false;  // has a prior pose and a depth
  Eigen::Matrix3d R_cam_world = Eigen::Matrix3d::Identity();
  Eigen::Vector3d t_cam_world = Eigen::Vector3d::Zero();
  double depth_m = 0;  // typical scene depth seen by this view (median of its points)
};

// Covisible pairs by the frusta at each view's depth (pinhole fx fy cx cy, width x height). Views not
// valid pair with none.
std::vector<ImagePair> covisible_pairs(const std::vector<uint32_t>& images,
                                       const std::vector<PairView>& views, double fx, double fy, double cx,
                                       double cy, int width, int height, const PairOptions& options);

}  // namespace litgs::host::frontend
