// `litgs-engine refine SCENE [--no-anchors] [--no-planes] [--alpha-min A --alpha-max B] [--rounds N]
// [--threads T]`: LiDAR-plane-constrained bundle adjustment of the scene's poses (docs/refinement.md).
#include <CLI/CLI.hpp>
#include <algorithm>
#include <iomanip>
#include <iostream>
#include <memory>

#include "host/refine/refine_option_names.h"
#include "host/refine/scene_refine.h"
#include "tools/commands.h"

namespace litgs::tools {

void add_refine_command(CLI::App& app) {
  namespace R = host::refine_option;
  CLI::App* c =
      app.add_subcommand("refine", "Refine the scene's poses: anchors, LiDAR planes, bundle adjustment");
  auto scene = std::make_shared<std::filesystem::path>();
  auto o = std::make_shared<host::refine::SceneRefineOptions>();
  auto planes = std::make_shared<bool>(true);
  c->add_option("scene", *scene, "Scene directory")->required()->check(CLI::ExistingDirectory);
  c->add_option(R::kAnchors.flag, o->anchors, R::kAnchors.help)->capture_default_str();
  auto no_anchors = std::make_shared<bool>(false);
  c->add_flag("--no-anchors", *no_anchors, "The same as --anchors off");
  c->add_flag(R::kPlanes.flag, *planes, R::kPlanes.help);
  c->add_flag(R::kScans.flag, o->refine.use_scans, R::kScans.help);
  c->add_option("--scan-sigma", o->refine.ba.scan_sigma_m, "Scan point-to-plane sigma, metres")
      ->capture_default_str()
      ->check(CLI::PositiveNumber);
  c->add_option("--scan-weight", o->refine.ba.scan_weight, "Weight of each scan point-to-plane residual")
      ->capture_default_str()
      ->check(CLI::NonNegativeNumber);
  c->add_flag("--points-on-scan-map,!--points-on-lidar-map", o->refine.scan_alignment.points_on_scan_map,
              "Once the scans join, hold the track points to the planes of the map the scans build each "
              "round (--points-on-lidar-map: to lidar/map.pcd in every round)");
  c->add_option("--scan-gate", o->refine.scan_alignment.gate_start_m,
                "Scan point-to-plane gate of the first round, metres (halved each round, floor 3 cm)")
      ->capture_default_str()
      ->check(CLI::PositiveNumber);
  c->add_option("--scans-from-round", o->refine.scan_alignment.from_round,
                "Round (0-based) in which the scans join the solve")
      ->capture_default_str();
  c->add_option("--scan-points", o->refine.scan_alignment.residual_points_per_scan,
                "Scan points per scan held to the map's planes")
      ->capture_default_str()
      ->check(CLI::PositiveNumber);
  c->add_option("--alpha-min", o->refine.weights.alpha_min,
                "Anchors' share of a frame's weight, slowest frames")
      ->capture_default_str();
  c->add_option("--alpha-max", o->refine.weights.alpha_max, "... and fastest frames")->capture_default_str();
  c->add_option(R::kRounds.flag, o->refine.rounds, R::kRounds.help)->capture_default_str();
  c->add_option(R::kThreads.flag, o->refine.threads, R::kThreads.help)->capture_default_str();
  c->add_option("--window", o->refine.window, "Frames per local window in round 1 (0: none)")
      ->capture_default_str();
  c->add_option("--pixel-loss-px", o->refine.ba.pixel_loss_px,
                "Cauchy scale of the reprojection residual, pixels")
      ->capture_default_str()
      ->check(CLI::PositiveNumber);
  c->add_option(R::kTracks.flag, o->tracks, R::kTracks.help)->capture_default_str();
  c->add_option("--outliers", o->synthetic.outlier_fraction, "Oracle tracks: fraction of wrong matches")
      ->capture_default_str();
  c->add_option("--pixel-noise", o->synthetic.pixel_noise_px, "Oracle tracks: pixel noise (px)")
      ->capture_default_str();
  c->add_option("--anchor-track-length", o->synthetic.anchor_track_length,
                "Oracle tracks: an anchor's track lasts up to N frames, then a new one starts where it is "
                "seen again (0: one track through every frame that sees it)")
      ->capture_default_str()
      ->check(CLI::NonNegativeNumber);
  c->add_option(
       "--min-frame-observations", o->refine.min_frame_observations,
       "Stop (keeping the priors) when more than half of the frames have fewer observations (0: off)")
      ->capture_default_str();
  c->add_option("--holdout-every", o->refine.holdout.every,
                "Hold every Nth track back from the solve; refined poses that explain them worse than the "
                "priors are not kept (0: no guard)")
      ->capture_default_str();
  auto absolute = std::make_shared<bool>(false);
  c->add_option(R::kPriors.flag, o->priors, R::kPriors.help)->capture_default_str();
  c->add_option(
       "--odometry-rotation-sigma", o->refine.ba.odometry_sigma_r_rad,
       "Odometry priors: orientation prior on every frame, radians (plus 0.0005 per metre travelled; 0: "
       "off)")
      ->capture_default_str();
  c->add_option("--relative-rotation-sigma", o->refine.ba.rel_sigma_r_rad,
                "Odometry priors: rotation sigma between consecutive frames, radians (plus 0.002 per metre "
                "between them)")
      ->capture_default_str();
  c->add_option("--odometry-position-sigma", o->refine.ba.odometry_sigma_t_m,
                "Odometry priors: position prior on every frame, metres (plus 0.02 per metre travelled: the "
                "map shares the odometry's frame; 0: off)")
      ->capture_default_str();
  c->add_option(
       "--scan-check-every", o->scan_check.every,
       "After the solve, check the scans the map held out (a scene without any: every Nth scan) "
       "against its planes; refined poses that fit them worse than the priors are not kept (0: no check)")
      ->capture_default_str();
  c->add_flag("--absolute-priors", *absolute, "The same as --priors absolute");
  c->add_option("--control-points", o->control_points_csv,
                "Surveyed control points (CSV: ID,X,Y,Z,accuracy) to check the poses with (needs --markers)")
      ->check(CLI::ExistingFile);
  c->add_option("--markers", o->markers_xml,
                "Metashape camera XML with the control points' image observations")
      ->check(CLI::ExistingFile);
  c->callback([scene, o, no_anchors, planes, absolute] {
    if (*absolute) o->priors = "absolute";
    if (*no_anchors) o->anchors = "off";
    o->refine.use_planes = *planes;
    const host::refine::SceneRefineReport r = host::refine::refine_scene(*scene, *o);
    const auto& rr = r.refine;
    std::cout << std::fixed << std::setprecision(3) << "refine: " << rr.outcome << " (" << rr.status << "); "
              << r.tracks << " tracks, " << r.priors << " priors; " << rr.frames << " frames, "
              << r.points_written << " points (" << rr.anchor_association.anchored_tracks << " anchored), "
              << rr.rounds.size() << " rounds in " << rr.seconds << " s; reprojection RMS "
              << rr.before.reprojection_rms_px << " -> " << rr.after.reprojection_rms_px << " px";
    if (rr.after.behind_camera > 0)
      std::cout << " (" << rr.after.behind_camera << " observations behind their camera left out)";
    std::cout << ", plane RMS " << rr.before.plane_rms_m << " -> " << rr.after.plane_rms_m << " m";
    const auto first_scans =
        std::find_if(rr.rounds.begin(), rr.rounds.end(),
                     [](const host::refine::RoundReport& x) { return x.scans.links > 0; });
    if (first_scans != rr.rounds.end())
      std::cout << ", scan RMS " << first_scans->scan_rms_before_m << " -> "
                << rr.rounds.back().scan_rms_after_m << " m (" << first_scans->scans.scans << " scans)";
    if (r.has_truth) std::cout << "; ATE " << r.ate_before_m << " -> " << r.ate_after_m << " m";
    if (r.ate_rejected_m >= 0)
      std::cout << " (the solve the guards turned down: " << r.ate_rejected_m << " m)";
    std::cout << "\n";
    if (r.control)
      std::cout << "control points: median reprojection " << r.control->median_prior_px
                << " px through the prior poses, " << r.control->median_refined_px
                << " px through the refined poses (" << r.control->observations << " observations)\n";
    for (const auto& note : rr.notes) std::cout << "  note: " << note << "\n";
  });
}

}  // namespace litgs::tools
