#include "host/frontend/pair_selection.h"

#include <Eigen/Geometry>
#include <algorithm>
#include <cmath>
#include <stdexcept>

namespace litgs::host::frontend {

void PairOptions::check() const {
  if (window < 1) throw std::invalid_argument("pairs: the window must be >= 1");
  if (!(max_axis_angle_deg > 0 && max_axis_angle_deg <= 180))
    throw std::invalid_argument("pairs: max_axis_angle_deg must be in (0, 180]");
  if (!(min_overlap >= 0 && min_overlap <= 1))
    throw std::invalid_argument("pairs: min_overlap must be in [0, 1]");
}

PairOptions parse_pairs(const std::string& text) {
  PairOptions o;
  auto window_of = [&](const std::string& prefix) {
    const std::string n = text.substr(prefix.size());
    size_t used = 0;
    long value = 0;
    try {
      value = std::stol(n, &used);
    } catch (const std::exception&) {
      used = 0;
    }
    if (used != n.size() || value < 1 || value > 100000)
      throw std::invalid_argument("--pairs " + text + ": the window after ':' must be an integer >= 1");
    return static_cast<size_t>(value);
  };
  if (text == "covisible") {
    o.mode = PairMode::kCovisible;
  } else if (text.rfind("covisible:", 0) == 0) {
    o.mode = PairMode::kCovisible;
    o.window = window_of("covisible:");
  } else if (text.rfind("sequential:", 0) == 0) {
    o.mode = PairMode::kSequential;
    o.window = window_of("sequential:");
  } else if (text == "exhaustive") {
    o.mode = PairMode::kExhaustive;
  } else {
    throw std::invalid_argument("--pairs " + text + ": expected covisible, sequential:N or exhaustive");
  }
  return o;
}

std::string pairs_name(const PairOptions& o) {
  switch (o.mode) {
    case PairMode::kCovisible:
      return "covisible:" + std::to_string(o.window);
    case PairMode::kSequential:
      return "sequential:" + std::to_string(o.window);
    case PairMode::kExhaustive:
      return "exhaustive";
  }
  return "?";
}

std::vector<ImagePair> sequential_pairs(const std::vector<uint32_t>& images, size_t window) {
  std::vector<ImagePair> out;
  for (size_t i = 0; i < images.size(); ++i)
    for (size_t j = i + 1; j < images.size() && j <= i + window; ++j) out.push_back({images[i], images[j]});
  return out;
}

std::vector<ImagePair> exhaustive_pairs(const std::vector<uint32_t>& images) {
  return sequential_pairs(images, images.size());
}

namespace {

// Fraction of a 7x6 grid of a's pixels, at a's depth, that b sees in front of it and inside its image.
double overlap(const PairView& a, const PairView& b, double fx, double fy, double cx, double cy, int width,
               int height) {
  constexpr int kCols = 7, kRows = 6;
  int seen = 0;
  for (int r = 0; r < kRows; ++r)
    for (int c = 0; c < kCols; ++c) {
      const double u = (c + 0.5) * width / kCols, v = (r + 0.5) * height / kRows;
      const Eigen::Vector3d ray((u - cx) / fx, (v - cy) / fy, 1.0);
      const Eigen::Vector3d world = a.R_cam_world.transpose() * (ray * a.depth_m - a.t_cam_world);
      const Eigen::Vector3d in_b = b.R_cam_world * world + b.t_cam_world;
      if (!(in_b.z() > 0)) continue;
      const double ub = fx * in_b.x() / in_b.z() + cx, vb = fy * in_b.y() / in_b.z() + cy;
      if (ub >= 0 && ub < width && vb >= 0 && vb < height) ++seen;
    }
  return static_cast<double>(seen) / (kCols * kRows);
}

}  // namespace

std::vector<ImagePair> covisible_pairs(const std::vector<uint32_t>& images,
                                       const std::vector<PairView>& views, double fx, double fy, double cx,
                                       double cy, int width, int height, const PairOptions& o) {
  o.check();
  const double min_cos = std::cos(o.max_axis_angle_deg * M_PI / 180.0);
  std::vector<ImagePair> out;
  for (size_t i = 0; i < images.size(); ++i)
    for (size_t j = i + 1; j < images.size(); ++j) {
      const PairView& a = views.at(images[i]);
      const PairView& b = views.at(images[j]);
      if (!a.valid || !b.valid) continue;
      // Viewing axes: the third rows of R_cam_world are the cameras' z axes in the world.
      if (a.R_cam_world.row(2).dot(b.R_cam_world.row(2)) < min_cos) continue;
      const double mean =
          0.5 * (overlap(a, b, fx, fy, cx, cy, width, height) + overlap(b, a, fx, fy, cx, cy, width, height));
      if (mean >= o.min_overlap) out.push_back({images[i], images[j]});
    }
  return out;
}

}  // namespace litgs::host::frontend
