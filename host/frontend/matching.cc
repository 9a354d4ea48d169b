#include "host/frontend/matching.h"

#include <limits>
#include <opencv2/core/hal/hal.hpp>
#include <opencv2/features2d.hpp>
#include <stdexcept>
#include <string>

namespace litgs::host::frontend {
namespace {

cv::Mat descriptor_mat(const ImageFeatures& f) {
  const int rows = static_cast<int>(f.keypoints.size());
  if (f.float_descriptors)
    return cv::Mat(rows, f.descriptor_bytes / 4, CV_32F, const_cast<uint8_t*>(f.descriptors.data()));
  return cv::Mat(rows, f.descriptor_bytes, CV_8U, const_cast<uint8_t*>(f.descriptors.data()));
}

void check_same_kind(const ImageFeatures& a, const ImageFeatures& b, const char* who) {
  if (a.float_descriptors != b.float_descriptors || a.descriptor_bytes != b.descriptor_bytes)
    throw std::invalid_argument(std::string(who) + ": the two images have different descriptor kinds");
}

// Whether the best match passes the second test: the ratio to the second best, or the cosine bound (unit
// vectors: cosine = 1 - d^2 / 2).
bool passes(double best, double second, const MatchOptions& o) {
  if (o.matcher == Matcher::kMnn) return 1 - best * best / 2 > o.min_cosine;
  return second == std::numeric_limits<double>::infinity() || best < o.ratio * second;
}

void check_matcher_kind(const ImageFeatures& a, const MatchOptions& o, const char* who) {
  if (o.matcher == Matcher::kMnn && !a.float_descriptors)
    throw std::invalid_argument(std::string(who) + ": the mnn matcher needs float descriptors (xfeat)");
}

}  // namespace

std::string matcher_name(Matcher m) {
  return m == Matcher::kMnn ? "mnn" : m == Matcher::kLighterGlue ? "lighterglue" : "ratio";
}

Matcher parse_matcher(const std::string& name) {
  if (name == "ratio") return Matcher::kRatio;
  if (name == "mnn") return Matcher::kMnn;
  if (name == "lighterglue") return Matcher::kLighterGlue;
  throw std::invalid_argument("unknown matcher '" + name + "' (ratio, mnn or lighterglue)");
}

void MatchOptions::check() const {
  if (!(ratio > 0 && ratio <= 1)) throw std::invalid_argument("match ratio must be in (0, 1]");
  if (!(min_cosine >= -1 && min_cosine < 1)) throw std::invalid_argument("min_cosine must be in [-1, 1)");
  if (!(min_score >= 0 && min_score < 1)) throw std::invalid_argument("min_score must be in [0, 1)");
}

std::vector<std::array<uint32_t, 2>> match_mutual(const ImageFeatures& a, const ImageFeatures& b,
                                                  const MatchOptions& o) {
  o.check();
  std::vector<std::array<uint32_t, 2>> out;
  if (a.keypoints.empty() || b.keypoints.empty()) return out;
  check_same_kind(a, b, "match_mutual");
  check_matcher_kind(a, o, "match_mutual");
  cv::BFMatcher matcher(a.float_descriptors ? cv::NORM_L2 : cv::NORM_HAMMING);
  const cv::Mat da = descriptor_mat(a), db = descriptor_mat(b);
  std::vector<std::vector<cv::DMatch>> ab, ba;
  // The second neighbour serves only the ratio test.
  matcher.knnMatch(da, db, ab, o.matcher == Matcher::kRatio ? 2 : 1);
  matcher.knnMatch(db, da, ba, 1);
  for (const auto& m : ab) {
    if (m.empty()) continue;
    const cv::DMatch& best = m[0];
    if (!passes(best.distance, m.size() > 1 ? m[1].distance : std::numeric_limits<double>::infinity(), o))
      continue;
    const auto& back = ba[static_cast<size_t>(best.trainIdx)];
    if (back.empty() || back[0].trainIdx != best.queryIdx) continue;
    out.push_back({static_cast<uint32_t>(best.queryIdx), static_cast<uint32_t>(best.trainIdx)});
  }
  return out;
}

std::vector<std::array<uint32_t, 2>> match_mutual_among(const ImageFeatures& a, const ImageFeatures& b,
                                                        const std::vector<std::vector<uint32_t>>& allowed,
                                                        const MatchOptions& o) {
  o.check();
  std::vector<std::array<uint32_t, 2>> out;
  if (a.keypoints.empty() || b.keypoints.empty()) return out;
  check_same_kind(a, b, "match_mutual_among");
  check_matcher_kind(a, o, "match_mutual_among");
  if (allowed.size() != a.keypoints.size())
    throw std::invalid_argument("match_mutual_among: one candidate list per keypoint of a is needed");
  const size_t bytes = static_cast<size_t>(a.descriptor_bytes);
  // Distances as the matcher's norm: L2 for float rows, Hamming for bit strings.
  auto distance = [&](uint32_t i, uint32_t j) -> double {
    const uint8_t* da = a.descriptors.data() + i * bytes;
    const uint8_t* db = b.descriptors.data() + j * bytes;
    if (a.float_descriptors)
      return std::sqrt(static_cast<double>(cv::hal::normL2Sqr_(reinterpret_cast<const float*>(da),
                                                               reinterpret_cast<const float*>(db),
                                                               static_cast<int>(bytes / 4))));
    return cv::hal::normHamming(da, db, static_cast<int>(bytes));
  };
  constexpr double kInf = std::numeric_limits<double>::infinity();
  std::vector<double> best_of_b(b.keypoints.size(), kInf);
  std::vector<int64_t> best_i_of_b(b.keypoints.size(), -1);
  std::vector<int64_t> best_j(a.keypoints.size(), -1);
  std::vector<char> passes_test(a.keypoints.size(), 0);
  for (uint32_t i = 0; i < allowed.size(); ++i) {
    double first = kInf, second = kInf;
    for (uint32_t j : allowed[i]) {
      const double d = distance(i, j);
      if (d < first) {
        second = first;
        first = d;
        best_j[i] = j;
      } else if (d < second) {
        second = d;
      }
      if (d < best_of_b[j]) {
        best_of_b[j] = d;
        best_i_of_b[j] = i;
      }
    }
    passes_test[i] = best_j[i] >= 0 && passes(first, second, o);
  }
  for (uint32_t i = 0; i < allowed.size(); ++i)
    if (passes_test[i] && best_i_of_b[static_cast<size_t>(best_j[i])] == i)
      out.push_back({i, static_cast<uint32_t>(best_j[i])});
  return out;
}

}  // namespace litgs::host::frontend
