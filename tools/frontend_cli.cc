#include "tools/frontend_cli.h"

#include <CLI/CLI.hpp>
#include <iomanip>
#include <iostream>
#include <sstream>

#include "host/frontend/match_option_names.h"
#include "host/nn/xfeat_features.h"
namespace litgs::tools {

host::frontend::FrontendOptions FrontendCli::resolved() const {
  host::frontend::FrontendOptions o = options;
  o.features.type = host::frontend::parse_feature_type(features);
  o.features.grid_rows = o.features.grid_cols;  // --grid N is N x N
  o.match.matcher = matcher == "auto" ? (o.features.type == host::frontend::FeatureType::kXfeat
                                             ? host::frontend::Matcher::kMnn
                                             : host::frontend::Matcher::kRatio)
                                      : host::frontend::parse_matcher(matcher);
  o.pairs = host::frontend::parse_pairs(pairs);
  o.preprocess.clahe = clahe;
  o.prior_epipolar = !no_prior_epipolar;
  if (poses != "estimated" && poses != "truth")
    throw std::invalid_argument("--poses " + poses + ": expected estimated or truth");
  o.true_poses = poses == "truth";
  o = host::nn::with_learned_detector(o, model);
  o.check();
  return o;
}

void add_frontend_options(CLI::App& cmd, const std::shared_ptr<FrontendCli>& cli) {
  host::frontend::FrontendOptions& o = cli->options;
  namespace M = host::match_option;
  cmd.add_option(M::kFeatures.flag, cli->features, M::kFeatures.help)->capture_default_str();
  cmd.add_flag(M::kClahe.flag, cli->clahe, M::kClahe.help);
  cmd.add_option(M::kPairs.flag, cli->pairs, M::kPairs.help)->capture_default_str();
  cmd.add_option(M::kMaxKeypoints.flag, o.features.max_keypoints, M::kMaxKeypoints.help)
      ->capture_default_str();
  cmd.add_option(M::kThreads.flag, o.threads, M::kThreads.help)->capture_default_str();
  cmd.add_option(M::kXfeatScale.flag, o.features.xfeat_scale, M::kXfeatScale.help)->capture_default_str();
  cmd.add_option("--grid", o.features.grid_cols, "Grid bucketing: N x N cells (0: off)")
      ->capture_default_str();
  cmd.add_option("--keypoint-spacing", o.features.min_spacing_px,
                 "orb, sift, akaze: drop a keypoint nearer than this to a stronger one (pixels; 0: none)")
      ->capture_default_str();
  cmd.add_option("--clahe-clip", o.preprocess.clahe_clip_limit, "CLAHE clip limit")->capture_default_str();
  cmd.add_option("--clahe-tiles", o.preprocess.clahe_tiles, "CLAHE tile grid N x N")->capture_default_str();
  cmd.add_option("--stretch-window", o.preprocess.stretch_window,
                 "16-bit stretch over the N frames around each frame (0: the whole sequence)")
      ->capture_default_str();
  cmd.add_option(M::kMatcher.flag, cli->matcher, M::kMatcher.help)->capture_default_str();
  cmd.add_option("--ratio", o.match.ratio, "Ratio test bound (matcher ratio)")->capture_default_str();
  cmd.add_option("--min-cosine", o.match.min_cosine, "Cosine similarity bound (matcher mnn)")
      ->capture_default_str();
  cmd.add_option("--model", cli->model, "XFeat's ONNX model (default: the one embedded in the binary)")
      ->check(CLI::ExistingFile);
  cmd.add_option("--magsac-px", o.verify.max_error_px, "MAGSAC threshold, pixels")->capture_default_str();
  cmd.add_option("--prior-epipolar-px", o.verify.prior_epipolar_px,
                 "Reject matches this far from the prior poses' epipolar lines (pixels)")
      ->capture_default_str();
  cmd.add_flag("--no-prior-epipolar", cli->no_prior_epipolar, "Do not use the prior poses' epipolar bound");
  cmd.add_flag("!--no-lidar-check", o.lidar_check.enabled,
               "Keep the matches the LiDAR map contradicts (default: reject them where the scene has a map)");
  cmd.add_option(
         "--lidar-transfer-px", o.lidar_check.max_transfer_px,
         "LiDAR check: a keypoint lifted to the map's depth must land this near its match, less the pair's "
         "common offset (pixels)")
      ->capture_default_str();
  cmd.add_option("--min-inliers", o.verify.min_inliers, "Verified matches a pair needs")
      ->capture_default_str();
  cmd.add_option("--max-error-px", o.triangulation.max_error_px,
                 "Triangulation: a view agrees with a point within this reprojection error")
      ->capture_default_str();
  cmd.add_option("--poses", cli->poses, "Priors: estimated (poses.txt) | truth (gt/poses.txt)")
      ->capture_default_str();
  cmd.add_flag("!--no-split-conflicts", o.split_conflicts,
               "Refuse a match that would put two keypoints of one image in a track (default: split such "
               "tracks by the prior poses)");
  cmd.add_option("--conflict-px", o.conflicts.max_error_px,
                 "Splitting conflicting tracks: reprojection bound through the prior poses, pixels")
      ->capture_default_str();
  cmd.add_option("--min-views", o.triangulation.min_views, "Views that must agree with a point")
      ->capture_default_str();
  cmd.add_option("--min-angle", o.triangulation.min_angle_deg, "Triangulation angle, degrees")
      ->capture_default_str();
}

host::frontend::FrontendProgress progress_printer() {
  // Redraws only when the bar grows (or the stage changes), so a log of it stays short.
  auto last = std::make_shared<std::pair<std::string, int>>("", -1);
  return [last](const std::string& stage, size_t done, size_t total) {
    const int width = 30;
    const int filled = total ? static_cast<int>(width * done / total) : width;
    if (stage == last->first && filled == last->second && done != total) return;
    *last = {stage, filled};
    std::cerr << '\r' << std::left << std::setw(10) << stage << " [" << std::string(filled, '#')
              << std::string(width - filled, ' ') << "] " << done << '/' << total << std::flush;
    if (done == total) std::cerr << '\n';
  };
}

void print_summary(std::ostream& out, const std::string& title, const host::frontend::FrontendResult& r) {
  const host::frontend::FrontendSummary& m = r.summary;
  const auto& o = r.options;
  out << std::fixed;
  out << title << " (" << host::frontend::feature_name(o.features.type)
      << (o.preprocess.clahe ? " + CLAHE" : "") << ", pairs " << host::frontend::pairs_name(o.pairs)
      << ", prior epipolar "
      << (o.prior_epipolar ? (std::ostringstream() << o.verify.prior_epipolar_px << " px").str()
                           : std::string("off"))
      << ")\n";
  out << std::setprecision(1) << "  images          " << m.images << " (" << m.frozen << " frozen, "
      << m.uniform << " uniform)\n"
      << "  keypoints/image " << m.keypoints_per_image << "\n"
      << "  pairs           " << m.pairs_tried << " tried, " << m.pairs_verified << " verified\n"
      << std::setprecision(3) << "  inlier ratio    " << m.inlier_ratio << " (" << m.verified_matches
      << " verified / " << m.mutual_matches << " mutual matches)\n";
  if (m.lidar_checked_images)
    out << "  LiDAR check     " << m.rejected_by_lidar
        << " essential-matrix inliers contradicted by the map, "
        << "rejected (" << m.lidar_checked_images << " images with map depth, " << std::setprecision(1)
        << o.lidar_check.max_transfer_px << " px)\n";
  out << std::setprecision(3) << "  tracks          " << m.tracks << " (" << m.track_conflicts << " of "
      << m.track_matches << " verified matches lost to conflicts; " << m.conflicting_components
      << " conflicting tracks split, " << m.conflict_keypoints_kept << " of their keypoints kept, "
      << m.conflict_keypoints_dropped << " dropped)\n"
      << "  points          " << m.points << "\n"
      << std::setprecision(2) << "  track length    " << m.mean_track_length << " (mean)\n"
      << std::setprecision(3) << "  reprojection    " << m.mean_error_px << " px (mean)\n";
  if (m.true_plane_median_m >= 0)
    out << std::setprecision(4) << "  true planes     " << m.true_plane_median_m << " m median, "
        << m.true_plane_mean_m << " m mean distance of the points to the nearest\n";
  out << std::setprecision(2) << "  seconds         preprocess " << m.seconds.preprocess << ", features "
      << m.seconds.features << ", pair selection " << m.seconds.pair_selection << ", matching "
      << m.seconds.matching << ", tracks+triangulation " << m.seconds.triangulation << ", total "
      << m.seconds.total << "\n";
  for (const auto& note : m.notes) out << "  note: " << note << "\n";
}

}  // namespace litgs::tools
