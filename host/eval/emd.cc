#include "host/eval/emd.h"

#include <algorithm>
#include <cmath>
#include <numeric>
#include <random>
#include <stdexcept>
#include <string>

#include "host/eval/assignment.h"

namespace litgs::host {

double earth_movers_distance(const std::vector<Eigen::Vector3d>& a, const std::vector<Eigen::Vector3d>& b) {
  if (a.size() != b.size())
    throw std::invalid_argument("earth_movers_distance: the sets differ in size (" +
                                std::to_string(a.size()) + " and " + std::to_string(b.size()) + ")");
  if (a.empty()) return 0;
  const Assignment m =
      min_cost_assignment(a.size(), [&](size_t i, size_t j) { return (a[i] - b[j]).norm(); });
  return m.total_cost / static_cast<double>(a.size());
}

std::vector<Eigen::Vector3d> sample_by_weight(const std::vector<Eigen::Vector3d>& points,
                                              const std::vector<double>& weights, size_t n, uint64_t seed) {
  if (weights.size() != points.size())
    throw std::invalid_argument("sample_by_weight: " + std::to_string(weights.size()) + " weights for " +
                                std::to_string(points.size()) + " points");
  double total = 0;
  for (double w : weights) {
    if (!(w >= 0) || !std::isfinite(w))
      throw std::invalid_argument("sample_by_weight: a weight is negative or not finite");
    total += w;
  }
  if (!(total > 0)) throw std::invalid_argument("sample_by_weight: every weight is 0 (nothing to draw)");
  // Inverse transform sampling on the cumulative weights: the draw depends only on the seed and
  // std::mt19937_64 (fully specified), not on a library's distribution classes.
  std::vector<double> cumulative(weights.size());
  std::partial_sum(weights.begin(), weights.end(), cumulative.begin());
  std::mt19937_64 rng(seed);
  std::vector<Eigen::Vector3d> out;
  out.reserve(n);
  for (size_t k = 0; k < n; ++k) {
    const double u = static_cast<double>(rng() >> 11) * 0x1.0p-53 * total;  // [0, total)
    size_t i =
        static_cast<size_t>(std::upper_bound(cumulative.begin(), cumulative.end(), u) - cumulative.begin());
    i = std::min(i, points.size() - 1);
    out.push_back(points[i]);
  }
  return out;
}

std::vector<Eigen::Vector3d> sample_uniform(const std::vector<Eigen::Vector3d>& points, size_t n,
                                            uint64_t seed) {
  // A partial Fisher-Yates shuffle of the indices.
  std::vector<size_t> index(points.size());
  std::iota(index.begin(), index.end(), size_t{0});
  n = std::min(n, points.size());
  std::mt19937_64 rng(seed);
  std::vector<Eigen::Vector3d> out;
  out.reserve(n);
  for (size_t k = 0; k < n; ++k) {
    const size_t j = k + static_cast<size_t>(rng() % (points.size() - k));
    std::swap(index[k], index[j]);
    out.push_back(points[index[k]]);
  }
  return out;
}

void EmdOptions::check() const {
  if (samples < 1) throw std::invalid_argument("EMD samples must be at least 1");
  if (rounds < 1) throw std::invalid_argument("EMD rounds must be at least 1");
}

EmdResult gaussian_emd(const std::vector<Eigen::Vector3d>& centres, const std::vector<double>& opacities,
                       const std::vector<Eigen::Vector3d>& reference, const EmdOptions& o) {
  o.check();
  if (reference.empty()) throw std::invalid_argument("EMD: the reference cloud is empty");
  EmdResult r;
  r.samples = std::min(o.samples, reference.size());
  r.rounds = o.rounds;
  r.weighted_by_opacity = o.weight_by_opacity;
  std::vector<double> per_round;
  for (uint32_t k = 0; k < o.rounds; ++k) {
    // A stream per draw, so that the reference draws do not depend on the model's size.
    const uint64_t seed = o.seed + 3 * uint64_t{k};
    const auto a = o.weight_by_opacity
                       ? sample_by_weight(centres, opacities, r.samples, seed)
                       : sample_by_weight(centres, std::vector<double>(centres.size(), 1.0), r.samples, seed);
    const auto b = sample_uniform(reference, r.samples, seed + 1);
    per_round.push_back(earth_movers_distance(a, b));
    r.floor_m += earth_movers_distance(sample_uniform(reference, r.samples, seed + 2), b) / o.rounds;
  }
  r.mean_m = std::accumulate(per_round.begin(), per_round.end(), 0.0) / static_cast<double>(per_round.size());
  if (per_round.size() > 1) {
    double ss = 0;
    for (double e : per_round) ss += (e - r.mean_m) * (e - r.mean_m);
    r.std_m = std::sqrt(ss / static_cast<double>(per_round.size() - 1));
  }
  return r;
}

}  // namespace litgs::host
