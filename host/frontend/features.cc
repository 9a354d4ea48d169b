#include "host/frontend/features.h"

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <numeric>
#include <opencv2/features2d.hpp>
#include <stdexcept>
#include <unordered_map>

namespace litgs::host::frontend {

std::string feature_name(FeatureType type) {
  switch (type) {
    case FeatureType::kOrb:
      return "orb";
    case FeatureType::kSift:
      return "sift";
    case FeatureType::kAkaze:
      return "akaze";
    case FeatureType::kXfeat:
      return "xfeat";
  }
  return "?";
}

FeatureType parse_feature_type(const std::string& name) {
  if (name == "orb") return FeatureType::kOrb;
  if (name == "sift") return FeatureType::kSift;
  if (name == "akaze") return FeatureType::kAkaze;
  if (name == "xfeat") return FeatureType::kXfeat;
  throw std::invalid_argument("unknown feature type '" + name + "' (orb, sift, akaze or xfeat)");
}

void FeatureOptions::check() const {
  if (max_keypoints < 1 || max_keypoints > 1000000)
    throw std::invalid_argument("max_keypoints must be in 1..1000000, got " + std::to_string(max_keypoints));
  if (grid_cols < 0 || grid_rows < 0 || grid_cols > 256 || grid_rows > 256 ||
      (grid_cols == 0) != (grid_rows == 0))
    throw std::invalid_argument("grid cells must be both 0 or both in 1..256");
  if (!(min_spacing_px >= 0 && min_spacing_px <= 64))
    throw std::invalid_argument("min_spacing_px must be in 0..64, got " + std::to_string(min_spacing_px));
  if (!(xfeat_scale >= 0.25 && xfeat_scale <= 4))
    throw std::invalid_argument("xfeat_scale must be in 0.25..4, got " + std::to_string(xfeat_scale));
}

std::vector<size_t> spaced_keypoints(const std::vector<float>& x, const std::vector<float>& y,
                                     const std::vector<float>& response, double min_spacing) {
  std::vector<size_t> order(x.size());
  std::iota(order.begin(), order.end(), size_t{0});
  if (!(min_spacing > 0)) return order;
  std::stable_sort(order.begin(), order.end(), [&](size_t a, size_t b) { return response[a] > response[b]; });
  // Kept keypoints by grid cell of side min_spacing: a rival lies in the 3 x 3 cells around.
  std::unordered_map<int64_t, std::vector<size_t>> cells;
  const auto cell_of = [&](double v) { return static_cast<int64_t>(std::floor(v / min_spacing)); };
  const auto key = [](int64_t cx, int64_t cy) { return cx * 1000003 + cy; };
  constexpr double kSamePositionPx = 1e-3;
  std::vector<size_t> kept;
  for (size_t i : order) {
    const int64_t cx = cell_of(x[i]), cy = cell_of(y[i]);
    bool near = false;
    for (int64_t dy = -1; dy <= 1 && !near; ++dy)
      for (int64_t dx = -1; dx <= 1 && !near; ++dx) {
        const auto c = cells.find(key(cx + dx, cy + dy));
        if (c == cells.end()) continue;
        for (size_t j : c->second) {
          const double d = std::hypot(double(x[i]) - x[j], double(y[i]) - y[j]);
          if (d > kSamePositionPx && d < min_spacing) {
            near = true;
            break;
          }
        }
      }
    if (near) continue;
    cells[key(cx, cy)].push_back(i);
    kept.push_back(i);
  }
  std::sort(kept.begin(), kept.end());
  return kept;
}

std::vector<size_t> bucket_keypoints(const std::vector<float>& x, const std::vector<float>& y,
                                     const std::vector<float>& response, int width, int height, int budget,
                                     int grid_cols, int grid_rows) {
  std::vector<size_t> order(x.size());
  std::iota(order.begin(), order.end(), size_t{0});
  std::stable_sort(order.begin(), order.end(), [&](size_t a, size_t b) { return response[a] > response[b]; });
  const size_t cap = static_cast<size_t>(std::max(budget, 0));
  std::vector<char> taken(x.size(), 0);
  std::vector<size_t> kept;
  if (grid_cols > 0 && grid_rows > 0 && x.size() > cap) {
    const size_t cells = static_cast<size_t>(grid_cols) * grid_rows;
    const size_t quota = cap / cells;
    std::vector<size_t> used(cells, 0);
    for (size_t i : order) {
      const int cx = std::clamp(static_cast<int>(static_cast<double>(x[i]) * grid_cols / std::max(width, 1)),
                                0, grid_cols - 1);
      const int cy = std::clamp(static_cast<int>(static_cast<double>(y[i]) * grid_rows / std::max(height, 1)),
                                0, grid_rows - 1);
      size_t& n = used[static_cast<size_t>(cy) * grid_cols + cx];
      if (n < quota) {
        ++n;
        taken[i] = 1;
        kept.push_back(i);
      }
    }
  }
  for (size_t i : order) {
    if (kept.size() >= cap) break;
    if (!taken[i]) kept.push_back(i);
  }
  std::sort(kept.begin(), kept.end());
  return kept;
}

namespace {

cv::Ptr<cv::Feature2D> make_detector(const FeatureOptions& o) {
  // Thresholds below OpenCV's defaults: thermal frames have little contrast, and the budget and the grid
  // decide what is kept. SIFT's 0.02 is COLMAP's default peak threshold in OpenCV's units.
  switch (o.type) {
    case FeatureType::kOrb:
      return cv::ORB::create(3 * o.max_keypoints, 1.2f, 8, 31, 0, 2, cv::ORB::HARRIS_SCORE, 31, 5);
    case FeatureType::kSift:
      return cv::SIFT::create(0, 3, 0.02, 10, 1.6);
    case FeatureType::kAkaze:
      return cv::AKAZE::create(cv::AKAZE::DESCRIPTOR_MLDB, 0, 3, 0.0005f, 4, 4, cv::KAZE::DIFF_PM_G2);
    case FeatureType::kXfeat:
      break;
  }
  throw std::invalid_argument("unknown feature type");
}

}  // namespace

ImageFeatures detect_features(const Gray8& image, const FeatureOptions& o) {
  o.check();
  if (o.type == FeatureType::kXfeat)
    throw std::invalid_argument("xfeat runs on the Vulkan device: the front end needs a learned detector");
  ImageFeatures f;
  f.float_descriptors = o.type == FeatureType::kSift;
  if (image.pixels.empty()) return f;
  const auto [lo, hi] = std::minmax_element(image.pixels.begin(), image.pixels.end());
  if (*lo == *hi) return f;  // no texture at all: nothing to detect
  const cv::Mat m(image.height, image.width, CV_8UC1, const_cast<uint8_t*>(image.pixels.data()));
  cv::Ptr<cv::Feature2D> detector = make_detector(o);
  std::vector<cv::KeyPoint> all;
  detector->detect(m, all);
  std::vector<float> x, y, r;
  for (const auto& k : all) {
    x.push_back(k.pt.x);
    y.push_back(k.pt.y);
    r.push_back(k.response);
  }
  if (o.min_spacing_px > 0) {
    std::vector<cv::KeyPoint> spaced;
    std::vector<float> sx, sy, sr;
    for (size_t i : spaced_keypoints(x, y, r, o.min_spacing_px)) {
      spaced.push_back(all[i]);
      sx.push_back(x[i]);
      sy.push_back(y[i]);
      sr.push_back(r[i]);
    }
    all.swap(spaced);
    x.swap(sx);
    y.swap(sy);
    r.swap(sr);
  }
  std::vector<cv::KeyPoint> kept;
  for (size_t i :
       bucket_keypoints(x, y, r, image.width, image.height, o.max_keypoints, o.grid_cols, o.grid_rows))
    kept.push_back(all[i]);
  cv::Mat descriptors;
  if (!kept.empty()) detector->compute(m, kept, descriptors);  // may drop keypoints near the border
  if (descriptors.empty()) return f;
  if (f.float_descriptors && descriptors.type() != CV_32F) descriptors.convertTo(descriptors, CV_32F);
  f.descriptor_bytes = static_cast<int>(descriptors.cols * descriptors.elemSize());
  f.descriptors.resize(static_cast<size_t>(descriptors.rows) * f.descriptor_bytes);
  for (int i = 0; i < descriptors.rows; ++i)
    std::copy_n(descriptors.ptr<uint8_t>(i), f.descriptor_bytes,
                f.descriptors.data() + static_cast<size_t>(i) * f.descriptor_bytes);
  // OpenCV's SIFT doubles the image first (bilinear, pixel centres mapped as (x + 0.5) / 2 - 0.5) but halves
  // the coordinates found there as x / 2: every keypoint lands a quarter pixel right of and below its
  // feature. Uncorrected, that bias moved the refined poses against the LiDAR map (docs/experiments.md,
  // "the refinement on the engine's own tracks", issue 44; FrontendFeatures.SiftKeypointsSitOnTheFeature).
  const float bias = o.type == FeatureType::kSift ? 0.25f : 0.0f;
  for (const auto& k : kept) f.keypoints.push_back({k.pt.x - bias, k.pt.y - bias, k.size, k.angle});
  return f;
}

}  // namespace litgs::host::frontend
