// The confidence-aware weights change a solution, in the expected direction: a frame whose anchored and
// other observations disagree lands nearer the anchored ones when alpha_t is larger, and nearer the
// observations of the heavier anchor when the anchor weights differ (host/refine/weights.h).
#include <gtest/gtest.h>

#include "host/refine/bundle_adjustment.h"
#include "host/refine/weights.h"

namespace litgs::host::refine {
namespace {

const PinholeCamera kCamera{200, 200, 159.5, 127.5, 320, 256};

Eigen::Vector2d project(const CameraPose& pose, const Eigen::Vector3d& X) {
  const Eigen::Vector3d x = pose.q_world_cam.conjugate() * (X - pose.p_world_cam);
  return {kCamera.fx * x.x() / x.z() + kCamera.cx, kCamera.fy * x.y() / x.z() + kCamera.cy};
}

// Three cameras 0.5 m apart facing a wall 5 m away; the outer two are fixed. In the middle frame the
// observations of the points `shifted(k)` are 2 px to the right of where the true pose puts them; the
// others are exact. Anchors: one per point, at the point (`anchor_of(k)`, -1 for none).
struct ConflictCase {
  std::vector<CameraPose> truth;
  std::vector<TrackPoint> points;
  std::vector<AnchorPoint> anchors;
  template <class Shifted, class AnchorOf>
  ConflictCase(Shifted shifted, AnchorOf anchor_of) {
    for (int f = 0; f < 3; ++f)
      truth.push_back({0.1 * f, Eigen::Quaterniond::Identity(), {0.5 * f - 0.5, 0, 0}});
    int k = 0;
    for (int i = -4; i <= 4; ++i)
      for (int j = -3; j <= 3; ++j, ++k) {
        TrackPoint t;
        t.X = Eigen::Vector3d(0.4 * i, 0.4 * j, 5.0);
        for (uint32_t f = 0; f < 3; ++f) {
          Eigen::Vector2d uv = project(truth[f], t.X);
          if (f == 1 && shifted(k)) uv.x() += 2.0;
          t.obs.push_back({f, uv});
        }
        t.anchor = anchor_of(k);
        if (t.anchor >= 0) anchors.push_back({t.X, Eigen::Matrix3d::Identity() * 1e-4});
        points.push_back(t);
      }
  }
  // The middle frame's refined pose, as the horizontal image shift of the wall's centre against the truth.
  double solve_middle_shift_px(std::vector<TrackPoint> pts) const {
    std::vector<CameraPose> poses = truth;
    BaProblem b;
    b.camera = kCamera;
    b.poses = &poses;
    b.priors = &truth;
    b.points = &pts;
    b.variable = {false, true, false};
    b.use_planes = false;
    b.use_anchor_priors = false;
    b.weights.rel_sigma_t_m = 100;  // the priors barely hold: the images decide
    b.weights.rel_sigma_r_rad = 100;
    b.weights.odometry_sigma_r_rad = 0;
    const BaSolveSummary s = solve_bundle_adjustment(b);
    EXPECT_TRUE(s.usable) << s.brief;
    const Eigen::Vector3d centre(0, 0, 5);
    return project(poses[1], centre).x() - project(truth[1], centre).x();
  }
};

TEST(RefineWeightsEffect, ALargerAlphaPullsTheFrameTowardsItsAnchoredObservations) {
  // Anchored points (every other one) are exact in the middle frame; the others are shifted 2 px.
  const ConflictCase c([](int k) { return k % 2 == 1; }, [](int k) { return k % 2 == 0 ? k / 2 : -1; });
  std::vector<double> anchor_weight(c.anchors.size(), 1.0);
  std::vector<double> shift;
  for (double alpha : {0.2, 0.5, 0.8}) {
    std::vector<TrackPoint> pts = c.points;
    assign_observation_weights(pts, {alpha, alpha, alpha}, anchor_weight, WeightOptions{});
    shift.push_back(c.solve_middle_shift_px(pts));
  }
  std::cout << "  middle frame's shift at alpha 0.2, 0.5, 0.8: " << shift[0] << ", " << shift[1] << ", "
            << shift[2] << " px\n";
  // Between the two camps (0 px: the anchored ones; 2 px: the others), and nearer the anchored ones the
  // larger alpha is.
  for (double s : shift) {
    EXPECT_GT(s, 0.0);
    EXPECT_LT(s, 2.0);
  }
  EXPECT_GT(shift[0], shift[1] + 0.1);
  EXPECT_GT(shift[1], shift[2] + 0.1);
}

TEST(RefineWeightsEffect, TheHeavierAnchorsObservationsWin) {
  // A third of the points unanchored and exact; of the anchored ones, half exact and half shifted in the
  // middle frame. The two halves' anchor weights decide where the frame lands within alpha's share.
  const ConflictCase c([](int k) { return k % 3 == 2; }, [](int k) { return k % 3 == 0 ? -1 : k; });
  auto shift_with = [&](double exact_weight, double shifted_weight) {
    std::vector<double> w(c.points.size(), 1.0);  // indexed by anchor = the point's index
    for (size_t k = 0; k < w.size(); ++k) w[k] = k % 3 == 2 ? shifted_weight : exact_weight;
    std::vector<TrackPoint> pts = c.points;
    assign_observation_weights(pts, {0.6, 0.6, 0.6}, w, WeightOptions{});
    return c.solve_middle_shift_px(pts);
  };
  const double exact_heavy = shift_with(4.0, 0.25), equal = shift_with(1.0, 1.0),
               shifted_heavy = shift_with(0.25, 4.0);
  std::cout << "  middle frame's shift, exact anchors heavy / equal / shifted anchors heavy: " << exact_heavy
            << ", " << equal << ", " << shifted_heavy << " px\n";
  EXPECT_LT(exact_heavy, equal - 0.1);
  EXPECT_LT(equal, shifted_heavy - 0.1);
  EXPECT_GT(exact_heavy, 0.0);
  EXPECT_LT(shifted_heavy, 2.0);
}

}  // namespace
}  // namespace litgs::host::refine
