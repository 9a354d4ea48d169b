// The method's confidence-aware weights (docs/refinement.md, "Weights"):
// - per frame, a motion score from linear and angular speed, each normalized by the sequence's median and
//   MAD, mapped by a sigmoid to alpha_t in [alpha_min, alpha_max]: the share of the frame's geometric
//   weight that its anchored observations carry;
// - per anchor, w'_k = 1 / sqrt(det Sigma_k) (m^-3), divided by the sequence median, with every eigenvalue
//   of Sigma_k raised to at least min_sigma_m^2 first so that a near-singular covariance cannot dominate;
// - per observation, the frame's total weight (its observation count) split: alpha_t to the anchored ones
//   in proportion to their anchor weights, 1 - alpha_t to the others in proportion to their proximity to
//   the nearest anchored observation, 1 / (1 + d / proximity_px).
#pragma once

#include <vector>

#include "host/refine/ba_types.h"

namespace litgs::host::refine {

struct WeightOptions {
  double alpha_min = 0.5, alpha_max = 0.7;
  double min_sigma_m = 0.001;  // eigenvalue floor of anchor covariances (standard deviation, metres)
  double proximity_px = 50;    // distance at which a non-anchor observation's share halves
  void check() const;          // std::invalid_argument naming the bad field
};

// Linear and angular speed per frame (central differences, one-sided at the ends), standardized by the
// sequence's median and 1.4826 * MAD (a floor keeps a constant-speed sequence finite), averaged.

std::vector<double> motion_scores(const std::vector<CameraPose>& poses);

// alpha_t = alpha_min + (alpha_max - alpha_min) * sigmoid(score_t).
std::vector<double> motion_alphas(const std::vector<double>& scores, const WeightOptions& options);

struct AnchorWeights {
  std::vector<double> weights;  // normalized: the median anchor has weight 1
  size_t guarded = 0;           // covariances with an eigenvalue raised to the floor
  double median_raw = 0;        // m^-3, the normalizer
};
AnchorWeights anchor_weights(const std::vector<AnchorPoint>& anchors, const WeightOptions& options);

// The covariance with its eigenvalues raised to at least floor_m2 (symmetrized first).
Eigen::Matrix3d guarded_covariance(const Eigen::Matrix3d& cov, double floor_m2, bool* raised = nullptr);

// Sets Observation::weight of every active observation (see the header comment); frames without anchored
// (or without non-anchored) observations keep weight 1 everywhere.
void assign_observation_weights(std::vector<TrackPoint>& points, const std::vector<double>& alphas,
                                const std::vector<double>& anchor_weight, const WeightOptions& options);

}  // namespace litgs::host::refine
