#include "kernels/nn/xfeat_keypoints_reference.h"

#include <algorithm>
#include <cmath>
#include <numeric>
#include <stdexcept>
#include <string>

namespace litgs::kernels::nn {
namespace {

constexpr int kCell = 8;
constexpr int kBins = kCell * kCell + 1;

// The 1/8-resolution map coordinate of a full-resolution position along a side of `full` pixels.
double map_coordinate(double p, int map_size, int full) {
  return p * map_size / std::max(full - 1, 1) - 0.5;
}

double tap(const FeatureMap& m, int c, int y, int x) {
  return y < 0 || x < 0 || y >= m.height || x >= m.width ? 0.0 : m.at(c, y, x);
}

// Keys' cubic convolution weights with a = -0.75 for the taps at -1, 0, 1, 2 from floor(t).
void cubic_weights(double t, double w[4]) {
  const double a = -0.75;
  auto near = [a](double d) { return ((a + 2) * d - (a + 3)) * d * d + 1; };       // |d| <= 1
  auto far = [a](double d) { return ((a * d - 5 * a) * d + 8 * a) * d - 4 * a; };  // 1 < |d| < 2
  w[0] = far(t + 1);
  w[1] = near(t);
  w[2] = near(1 - t);
  w[3] = far(2 - t);
}

}  // namespace

FeatureMap keypoint_heatmap(const FeatureMap& logits) {
  if (logits.channels != kBins)
    throw std::invalid_argument("keypoint_heatmap: 65 logits per cell, got " +
                                std::to_string(logits.channels));
  FeatureMap heat(1, logits.height * kCell, logits.width * kCell);
  for (int cy = 0; cy < logits.height; ++cy)
    for (int cx = 0; cx < logits.width; ++cx) {
      double top = logits.at(0, cy, cx);
      for (int b = 1; b < kBins; ++b) top = std::max(top, logits.at(b, cy, cx));
      double sum = 0;
      for (int b = 0; b < kBins; ++b) sum += std::exp(logits.at(b, cy, cx) - top);
      for (int b = 0; b < kBins - 1; ++b)
        heat.at(0, cy * kCell + b / kCell, cx * kCell + b % kCell) =
            std::exp(logits.at(b, cy, cx) - top) / sum;
    }
  return heat;
}

double sample_bilinear(const FeatureMap& m, int c, double x, double y, int width, int height) {
  const double u = map_coordinate(x, m.width, width), v = map_coordinate(y, m.height, height);
  const int x0 = static_cast<int>(std::floor(u)), y0 = static_cast<int>(std::floor(v));
  const double tx = u - x0, ty = v - y0;
  return (1 - ty) * ((1 - tx) * tap(m, c, y0, x0) + tx * tap(m, c, y0, x0 + 1)) +
         ty * ((1 - tx) * tap(m, c, y0 + 1, x0) + tx * tap(m, c, y0 + 1, x0 + 1));
}

FeatureMap keypoint_scores(const FeatureMap& heat, const FeatureMap& reliability,
                           const XfeatKeypointOptions& o) {
  if (heat.channels != 1 || reliability.channels != 1 || heat.width != reliability.width * kCell ||
      heat.height != reliability.height * kCell)
    throw std::invalid_argument("keypoint_scores: a heat map 8 times the reliability map's size");
  FeatureMap scores(1, heat.height, heat.width);
  const int r = o.nms_window / 2;
  for (int y = 0; y < heat.height; ++y)
    for (int x = 0; x < heat.width; ++x) {
      const double h = heat.at(0, y, x);
      if (!(h > o.threshold)) continue;
      bool largest = true;
      for (int dy = -r; dy <= r && largest; ++dy)
        for (int dx = -r; dx <= r; ++dx)
          if (y + dy >= 0 && x + dx >= 0 && y + dy < heat.height && x + dx < heat.width &&
              heat.at(0, y + dy, x + dx) > h) {
            largest = false;
            break;
          }
      if (largest) scores.at(0, y, x) = h * sample_bilinear(reliability, 0, x, y, heat.width, heat.height);
    }
  return scores;
}

std::vector<ScoredKeypoint> top_keypoints(const std::vector<float>& scores, int width, int height,
                                          uint32_t top_k) {
  if (scores.size() != size_t(width) * size_t(height))
    throw std::invalid_argument("top_keypoints: " + std::to_string(scores.size()) + " scores for " +
                                std::to_string(width) + "x" + std::to_string(height) + " pixels");
  std::vector<uint32_t> candidates;
  for (size_t i = 0; i < scores.size(); ++i)
    if (scores[i] > 0) candidates.push_back(static_cast<uint32_t>(i));
  const size_t k = std::min<size_t>(top_k, candidates.size());
  std::partial_sort(
      candidates.begin(), candidates.begin() + static_cast<std::ptrdiff_t>(k), candidates.end(),
      [&](uint32_t a, uint32_t b) { return scores[a] > scores[b] || (scores[a] == scores[b] && a < b); });
  std::vector<ScoredKeypoint> out(k);
  for (size_t i = 0; i < k; ++i)
    out[i] = {static_cast<float>(candidates[i] % uint32_t(width)),
              static_cast<float>(candidates[i] / uint32_t(width)), scores[candidates[i]]};
  return out;
}

FeatureMap normalize_channels(const FeatureMap& f) {
  FeatureMap out = f;
  for (int y = 0; y < f.height; ++y)
    for (int x = 0; x < f.width; ++x) {
      double sq = 0;
      for (int c = 0; c < f.channels; ++c) sq += f.at(c, y, x) * f.at(c, y, x);
      const double n = std::max(std::sqrt(sq), 1e-12);
      for (int c = 0; c < f.channels; ++c) out.at(c, y, x) = f.at(c, y, x) / n;
    }
  return out;
}

std::vector<double> sample_descriptors(const FeatureMap& m, const std::vector<ScoredKeypoint>& keypoints,
                                       int width, int height) {
  std::vector<double> out(keypoints.size() * size_t(m.channels));
  for (size_t k = 0; k < keypoints.size(); ++k) {
    const double u = map_coordinate(keypoints[k].x, m.width, width);
    const double v = map_coordinate(keypoints[k].y, m.height, height);
    const int x0 = static_cast<int>(std::floor(u)), y0 = static_cast<int>(std::floor(v));
    double wx[4], wy[4];
    cubic_weights(u - x0, wx);
    cubic_weights(v - y0, wy);
    double* d = &out[k * size_t(m.channels)];
    double sq = 0;
    for (int c = 0; c < m.channels; ++c) {
      double s = 0;
      for (int j = 0; j < 4; ++j)
        for (int i = 0; i < 4; ++i) s += wy[j] * wx[i] * tap(m, c, y0 - 1 + j, x0 - 1 + i);
      d[c] = s;
      sq += s * s;
    }
    const double n = std::max(std::sqrt(sq), 1e-12);
    for (int c = 0; c < m.channels; ++c) d[c] /= n;
  }
  return out;
}

XfeatKeypoints detect_keypoints(const FeatureMap& features, const FeatureMap& logits,
                                const FeatureMap& reliability, const XfeatKeypointOptions& o) {
  const FeatureMap heat = keypoint_heatmap(logits);
  const FeatureMap scores = keypoint_scores(heat, reliability, o);
  const std::vector<float> as_float(scores.values.begin(), scores.values.end());
  XfeatKeypoints out;
  out.keypoints = top_keypoints(as_float, scores.width, scores.height, o.top_k);
  out.descriptors = sample_descriptors(normalize_channels(features), out.keypoints, heat.width, heat.height);
  return out;
}

}  // namespace litgs::kernels::nn
