#include "host/refine/refine.h"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <stdexcept>

#include "host/refine/weights.h"
#include "io/robust_stats.h"

namespace litgs::host::refine {
namespace {

double seconds_since(std::chrono::steady_clock::time_point t) {
  return std::chrono::duration<double>(std::chrono::steady_clock::now() - t).count();
}

// A frame whose observations all repeat the previous frame's exactly (a camera's non-uniformity
// correction freezes the image): its observations say nothing about its own pose.
std::vector<bool> drop_frozen_frames(std::vector<TrackPoint>& points, size_t frames) {
  std::vector<size_t> shared(frames, 0), moved(frames, 0);
  for (const auto& p : points)
    for (size_t i = 1; i < p.obs.size(); ++i)
      if (p.obs[i].frame == p.obs[i - 1].frame + 1 && p.obs[i].frame < frames) {
        ++shared[p.obs[i].frame];
        moved[p.obs[i].frame] += (p.obs[i].uv - p.obs[i - 1].uv).norm() > 1e-6;
      }
  std::vector<bool> frozen(frames, false);
  for (size_t f = 1; f < frames; ++f) frozen[f] = shared[f] >= 5 && moved[f] == 0;
  for (auto& p : points)
    for (auto& ob : p.obs)
      if (ob.frame < frames && frozen[ob.frame]) ob.active = false;
  return frozen;
}

void deactivate_weak_points(std::vector<TrackPoint>& points, size_t* dropped) {
  for (auto& p : points)
    if (p.active && (p.active_observations() < 2 || !p.X.allFinite())) {
      p.active = false;
      if (dropped) ++*dropped;
    }
}

// Active observations of active points, per frame.
std::vector<size_t> frame_observations(const std::vector<TrackPoint>& points, size_t frames) {
  std::vector<size_t> count(frames, 0);
  for (const auto& p : points)
    if (p.active)
      for (const auto& ob : p.obs) count[ob.frame] += ob.active;
  return count;
}

}  // namespace

bool all_finite(const std::vector<CameraPose>& poses, const std::vector<TrackPoint>& points) {
  for (const auto& c : poses)
    if (!c.p_world_cam.allFinite() || !c.q_world_cam.coeffs().allFinite()) return false;
  for (const auto& p : points)
    if (p.active && !p.X.allFinite()) return false;
  return true;
}

size_t TrackPoint::active_observations() const {
  size_t n = 0;
  for (const auto& o : obs) n += o.active;
  return n;
}

void RefineOptions::check() const {
  if (rounds < 1) throw std::invalid_argument("refine: rounds must be >= 1");
  if (window == 1) throw std::invalid_argument("refine: window must be 0 (off) or >= 2 frames");
  if (!(reject_k > 0)) throw std::invalid_argument("refine: reject_k must be > 0");
  if (threads < 1) throw std::invalid_argument("refine: threads must be >= 1");
  if (max_iterations < 1) throw std::invalid_argument("refine: max_iterations must be >= 1");
  weights.check();
  holdout.check();
  scan_alignment.check();
  if (!(ba.scan_sigma_m > 0)) throw std::invalid_argument("refine: scan_sigma_m must be > 0");
  if (!(ba.scan_weight >= 0) || !std::isfinite(ba.scan_weight))
    throw std::invalid_argument("refine: scan_weight must be finite and >= 0");
}

ResidualStats residual_stats(const std::vector<TrackPoint>& points, const std::vector<CameraPose>& poses,
                             const PinholeCamera& camera) {
  ResidualStats s;
  std::vector<double> e;
  double sum2 = 0, anchored2 = 0, plane2 = 0;
  for (const auto& p : points) {
    if (!p.active) continue;
    for (const auto& ob : p.obs)
      if (ob.active) {
        ++s.observations;
        const double error = reprojection_error_px(poses[ob.frame], camera, p.X, ob.uv);
        if (!std::isfinite(error)) {
          ++s.behind_camera;
          continue;
        }
        e.push_back(error);
        sum2 += error * error;
        if (p.anchor >= 0) {
          ++s.anchored_observations;
          anchored2 += error * error;
        }
      }
    if (p.has_plane) {
      const double d = p.plane.n.dot(p.X - p.plane.l);
      plane2 += d * d;
      ++s.plane_points;
    }
  }
  if (!e.empty()) {
    s.reprojection_rms_px = std::sqrt(sum2 / static_cast<double>(e.size()));
    s.reprojection_median_px = io::median(e);
  }
  if (s.anchored_observations)
    s.anchored_reprojection_rms_px = std::sqrt(anchored2 / static_cast<double>(s.anchored_observations));
  if (s.plane_points) s.plane_rms_m = std::sqrt(plane2 / static_cast<double>(s.plane_points));
  return s;
}

namespace {

// The rounds of the solve with o.holdout's tracks held back, judged on them at the end.
RefineReport solve_and_judge(RefineInput& in, std::vector<CameraPose>& poses, const RefineOptions& o) {
  const auto start = std::chrono::steady_clock::now();
  RefineReport report;
  const size_t n = in.priors.size();
  if (poses.size() != n) throw std::invalid_argument("refine: poses and priors differ in count");
  report.frames = n;
  report.anchors = in.anchors.size();
  for (auto& p : in.points)
    for (auto& ob : p.obs)
      if (ob.frame >= n)
        throw std::invalid_argument("refine: an observation names frame " + std::to_string(ob.frame) +
                                    " of " + std::to_string(n));
  // Held back before anything else looks at the tracks: they judge the solve at the end.
  const std::vector<TrackPoint> held_out = hold_out_tracks(in.points, o.holdout);
  report.points = in.points.size();
  for (const auto& p : in.points) report.observations += p.obs.size();
  const std::vector<bool> frozen = drop_frozen_frames(in.points, n);
  report.frozen_frames = static_cast<size_t>(std::count(frozen.begin(), frozen.end(), true));
  for (const auto& p : in.points) report.untriangulated_points += !p.active;
  deactivate_weak_points(in.points, &report.untriangulated_points);

  const bool planes = o.use_planes && in.map && in.map->planar_count() > 0;
  const bool anchors = o.use_anchors && !in.anchors.empty();
  const bool scans = o.use_scans && !in.scans.empty();
  if (o.use_planes && !planes) report.notes.push_back("no LiDAR planes: the plane term is off");
  if (o.use_anchors && !anchors) report.notes.push_back("no anchors: the anchor weights and priors are off");
  if (anchors && o.rounds <= o.anchors_from_round)
    report.notes.push_back("anchors join in round " + std::to_string(o.anchors_from_round + 1) +
                           " (after a solve without them); with " + std::to_string(o.rounds) +
                           " round(s) they are not used");
  if (scans && o.rounds <= o.scan_alignment.from_round)
    report.notes.push_back("the scans join in round " + std::to_string(o.scan_alignment.from_round + 1) +
                           "; with " + std::to_string(o.rounds) + " round(s) they are not used");
  std::vector<double> anchor_w;
  std::vector<Eigen::Matrix3d> sqrt_info;
  std::vector<AnchorPoint> guarded_anchors;  // covariances guarded: the association's gate inverts them
  if (anchors) {
    const AnchorWeights aw = anchor_weights(in.anchors, o.weights);
    anchor_w = aw.weights;
    report.guarded_anchor_covariances = aw.guarded;
    report.anchor_weight_median_raw = aw.median_raw;
    for (const auto& a : in.anchors) {
      const Eigen::Matrix3d c = guarded_covariance(a.cov, o.weights.min_sigma_m * o.weights.min_sigma_m);
      sqrt_info.push_back(Eigen::Matrix3d(c.llt().matrixL()).inverse());
      guarded_anchors.push_back({a.p_world, c});
    }
  } else {
    for (auto& p : in.points) p.anchor = -1;
  }
  report.alphas = motion_alphas(motion_scores(in.priors), o.weights);
  std::unique_ptr<PlaneAssociator> associator;
  // With points_on_scan_map the track points take their planes from the map the scans build each round.
  const bool points_on_scans = scans && planes && o.scan_alignment.points_on_scan_map;
  if (planes) associator = std::make_unique<PlaneAssociator>(*in.map, in.camera);
  PlanarMap round_map;

  size_t active_points = 0;
  for (const auto& p : in.points) active_points += p.active;
  report.before = residual_stats(in.points, poses, in.camera);  // round 1 restates it after association
  const std::vector<size_t> per_frame = frame_observations(in.points, n);
  for (size_t c : per_frame) report.weak_frames += c < o.min_frame_observations;
  report.fewest_frame_observations = SIZE_MAX;
  for (size_t f = 0; f < n; ++f) {
    // A frame without any observation was left out upstream (the front end skips NUC-frozen frames).
    if (frozen[f] || per_frame[f] == 0) {
      report.frames_without_observations += !frozen[f];
      continue;
    }
    report.fewest_frame_observations = std::min(report.fewest_frame_observations, per_frame[f]);
  }
  if (report.fewest_frame_observations == SIZE_MAX) report.fewest_frame_observations = 0;
  if (n > 0) {
    std::vector<double> counts(per_frame.begin(), per_frame.end());
    report.median_frame_observations = io::median(counts);
  }
  if (in.points.empty()) {
    report.status = "stopped: no tracks (the front end found none to refine with); poses kept as the priors";
    report.stopped_early = true;
  } else if (active_points == 0) {
    report.status =
        "stopped: no point has two observations and a finite position (" +
        std::to_string(report.untriangulated_points) +
        " tracks could not be triangulated: no baseline, e.g. pure rotation); poses kept as the priors";
    report.stopped_early = true;
  } else if (2 * report.weak_frames > n) {
    char text[256];
    std::snprintf(text, sizeof text,
                  "stopped: too few tracks to refine the poses: %zu of %zu frames have fewer than %zu "
                  "observations (median %.0f); poses kept as the priors",
                  report.weak_frames, n, o.min_frame_observations, report.median_frame_observations);
    report.status = text;
    report.stopped_early = true;
  }
  for (size_t r = 0; r < o.rounds && !report.stopped_early; ++r) {
    const auto round_start = std::chrono::steady_clock::now();
    RoundReport rr;
    // Anchors live in the map's frame; projected through drifting priors they land on neighbouring
    // tracks (most of the street's pairs in round 1: docs/refinement.md, "Why the anchors hurt"): they
    // join once a solve has brought the poses there.
    // Both associations follow the poses as they improve.
    const bool anchors_now = anchors && r >= o.anchors_from_round;
    if (!anchors_now)
      for (auto& p : in.points) p.anchor = -1;
    if (anchors_now)
      report.anchor_association = associate_anchors(in.points, guarded_anchors, poses, in.camera,
                                                    planes ? in.map : nullptr, o.anchor_association, r);
    // The scans join from their round on, their map's voxel and gate schedule starting there.
    const bool scans_now = scans && r >= o.scan_alignment.from_round;
    const size_t scan_round = scans_now ? r - o.scan_alignment.from_round : 0;
    if (scans_now) {
      if (points_on_scans) associator.reset();  // it holds the previous round's map
      round_map = scan_map(in.scans, poses, scan_round, o.scan_alignment);
      if (points_on_scans) associator = std::make_unique<PlaneAssociator>(round_map, in.camera);
    }
    if (associator) rr.planes = associator->associate(in.points, poses, r, o.plane_association);
    std::vector<ScanPlaneLink> scan_links;
    if (scans_now) {
      scan_links = associate_scan_planes(in.scans, poses, round_map, scan_round, o.scan_alignment, rr.scans);
      rr.scan_rms_before_m = scan_plane_rms_m(scan_links, poses);
    }
    if (r == 0) report.before = residual_stats(in.points, poses, in.camera);
    rr.before = residual_stats(in.points, poses, in.camera);
    assign_observation_weights(in.points, report.alphas, anchor_w, o.weights);
    const std::vector<CameraPose> poses_backup = poses;
    const std::vector<TrackPoint> points_backup = in.points;
    BaProblem problem;
    problem.camera = in.camera;
    problem.poses = &poses;
    problem.priors = &in.priors;
    problem.points = &in.points;
    problem.anchors = anchors_now ? &in.anchors : nullptr;
    problem.anchor_sqrt_information = sqrt_info;
    problem.use_planes = planes;
    problem.scan_links = scans_now ? &scan_links : nullptr;
    problem.use_anchor_priors = anchors_now;
    problem.weights = o.ba;
    problem.threads = o.threads;
    problem.max_iterations = o.max_iterations;
    if (r == 0 && o.window >= 2 && n > o.window) {
      rr.local = true;
      for (size_t first = 0; first < n; first += o.window / 2) {
        problem.variable.assign(n, false);
        for (size_t f = first; f < std::min(n, first + o.window); ++f) problem.variable[f] = true;
        solve_bundle_adjustment(problem);
        ++rr.local_solves;
        if (first + o.window >= n) break;
      }
      problem.variable.clear();
    }
    rr.global = solve_bundle_adjustment(problem);
    if (!rr.global.usable || !all_finite(poses, in.points)) {
      poses = poses_backup;
      in.points = points_backup;
      report.status = "stopped in round " + std::to_string(r + 1) + ": Ceres returned " +
                      rr.global.termination + " (" + rr.global.brief +
                      "); the previous round's poses and points are kept";
      report.stopped_early = true;
    }
    rr.after = residual_stats(in.points, poses, in.camera);
    rr.scan_rms_after_m = scan_plane_rms_m(scan_links, poses);
    if (r + 1 < o.rounds && !report.stopped_early) {
      // Rejection between rounds: observations and plane links beyond the robust bound.
      std::vector<double> e, d;
      for (const auto& p : in.points) {
        if (!p.active) continue;
        for (const auto& ob : p.obs)
          if (ob.active) e.push_back(reprojection_error_px(poses[ob.frame], in.camera, p.X, ob.uv));
        if (p.has_plane) d.push_back(std::abs(p.plane.n.dot(p.X - p.plane.l)));
      }
      rr.reject_bound_px = io::robust_upper_bound(e, o.reject_k, o.reject_floor_px);
      rr.reject_bound_m = io::robust_upper_bound(d, o.reject_k, o.reject_floor_m);
      for (auto& p : in.points) {
        if (!p.active) continue;
        for (auto& ob : p.obs)
          if (ob.active &&
              !(reprojection_error_px(poses[ob.frame], in.camera, p.X, ob.uv) <= rr.reject_bound_px)) {
            ob.active = false;
            ++rr.rejected_observations;
          }
        if (p.has_plane && !(std::abs(p.plane.n.dot(p.X - p.plane.l)) <= rr.reject_bound_m)) {
          p.has_plane = false;
          p.plane_rejected = true;
          ++rr.rejected_planes;
        }
      }
      deactivate_weak_points(in.points, &rr.dropped_points);
    }
    rr.seconds = seconds_since(round_start);
    report.rounds.push_back(rr);
  }
  if (o.holdout.every > 0 && !report.rounds.empty()) {
    report.holdout = judge_on_held_out(held_out, in.priors, poses, in.camera, o.holdout);
    report.notes.push_back(report.holdout.summary);
    if (!report.holdout.keep_refined) {
      report.rejected_poses = poses;
      poses = in.priors;
      report.outcome = "kept the priors";
      report.status = "kept the priors: the refined poses explain the held-back tracks worse (median " +
                      std::to_string(report.holdout.refined_median_px) + " px against " +
                      std::to_string(report.holdout.prior_median_px) + " px through the priors)";
    }
  }
  if (report.stopped_early && report.outcome == "refined") report.outcome = "stopped";
  report.after = residual_stats(in.points, poses, in.camera);
  report.seconds = seconds_since(start);
  return report;
}

}  // namespace

RefineReport refine(RefineInput& in, std::vector<CameraPose>& poses, const RefineOptions& o) {
  o.check();
  if (o.holdout.every == 0) return solve_and_judge(in, poses, o);
  RefineInput every_track = in;
  std::vector<CameraPose> refit = poses;
  RefineReport judged = solve_and_judge(in, poses, o);
  if (judged.outcome != "refined") return judged;
  // The held-back tracks judged the solve worth keeping: solve again with them in it, as a cross-validation
  // refits on all the data (an eighth more tracks: docs/experiments.md, issue 44).
  RefineOptions all = o;
  all.holdout.every = 0;
  RefineReport r = solve_and_judge(every_track, refit, all);
  if (r.outcome != "refined") {
    judged.notes.push_back("the solve with the held-back tracks in it " + r.outcome + " (" + r.status +
                           "): the judged solve is kept");
    return judged;
  }
  in = std::move(every_track);
  poses = std::move(refit);
  r.holdout = judged.holdout;
  r.notes.insert(r.notes.begin(), judged.holdout.summary + "; then solved again with every track");
  r.seconds += judged.seconds;
  return r;
}

}  // namespace litgs::host::refine
