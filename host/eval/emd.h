// The earth mover's distance between reconstructed geometry and a reference point cloud, as the LIT-GS paper
// reports it: N points drawn from each side (the Gaussians' centres in proportion to their opacity, the
// reference cloud uniformly), each point a mass 1/N, and the exact optimal transport between the two sets
// (host/eval/assignment.h). The distance is the mean Euclidean distance of the optimal one-to-one matching,
// in metres: EMD = (1/N) min over permutations s of sum_i |a_i - b_s(i)|.
#pragma once

#include <Eigen/Core>
#include <cstdint>
#include <vector>

namespace litgs::host {

// The mean matched distance of the optimal one-to-one matching of two sets of the same size (metres);
// std::invalid_argument when the sizes differ. 0 for two empty sets.
double earth_movers_distance(const std::vector<Eigen::Vector3d>& a, const std::vector<Eigen::Vector3d>& b);

// `n` draws with replacement, point i drawn with probability weights[i] / sum(weights) (weights >= 0, finite,
// not all 0: std::invalid_argument otherwise).
std::vector<Eigen::Vector3d> sample_by_weight(const std::vector<Eigen::Vector3d>& points,
                                              const std::vector<double>& weights, size_t n, uint64_t seed);
// min(n, size) distinct points, uniformly without replacement.
std::vector<Eigen::Vector3d> sample_uniform(const std::vector<Eigen::Vector3d>& points, size_t n,
                                            uint64_t seed);

struct EmdOptions {
  size_t samples = 1000;  // N per side (fewer if the reference cloud has fewer points)
  uint32_t rounds = 3;    // independent draws; the result is their mean and standard deviation
  uint64_t seed = 0;
  // false: every Gaussian equally likely (a diagnostic: it separates where the model puts its opacity from
  // where its centres are).
  bool weight_by_opacity = true;
  void check() const;  // std::invalid_argument naming the bad field
};

struct EmdResult {
  double mean_m = 0;  // mean over the rounds of each round's EMD
  double std_m = 0;   // their sample standard deviation (0 with one round)
  // The sampling floor: the same measure between two independent draws of the reference itself (mean over
  // the rounds). Two finite samples of one surface are not at distance 0: with N points over a scene of size
  // L the floor is about L sqrt(log N / N), so a model's EMD reads against it, not against 0.
  double floor_m = 0;
  size_t samples = 0;
  uint32_t rounds = 0;
  bool weighted_by_opacity = true;
};

// EMD between Gaussian centres (drawn in proportion to `opacities`) and `reference`, both in one frame.
EmdResult gaussian_emd(const std::vector<Eigen::Vector3d>& centres, const std::vector<double>& opacities,
                       const std::vector<Eigen::Vector3d>& reference, const EmdOptions& options);

}  // namespace litgs::host
