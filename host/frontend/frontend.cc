#include "host/frontend/frontend.h"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <mutex>
#include <nlohmann/json.hpp>
#include <optional>
#include <stdexcept>
#include <thread>

#include "host/frontend/parallel.h"
#include "host/frontend/tracks.h"
#include "io/export_scene.h"
#include "io/scene.h"

namespace litgs::host::frontend {
namespace {

using Clock = std::chrono::steady_clock;
double since(Clock::time_point t0) {
  return std::chrono::duration<double>(Clock::now() - t0).count();
}

struct Pose {
  Eigen::Matrix3d R_cam_world;
  Eigen::Vector3d t_cam_world;
};

// Everything the matching and triangulation stages share.
struct Context {
  const FrontendOptions& o;
  const io::CameraIntrinsics& camera;
  PinholeK K;
  std::vector<std::optional<Pose>> poses;
  std::vector<ImageFeatures> features;
  std::vector<std::vector<Eigen::Vector2d>> undistorted;    // pixels of the ideal pinhole
  std::vector<std::optional<LidarDepthImage>> lidar_depth;  // per image; empty without the LiDAR check
  const FrontendProgress& progress;
};

void report(const Context& c, const char* stage, size_t done, size_t total) {
  if (c.progress) c.progress(stage, done, total);
}

std::optional<RelativePose> relative_prior(const Context& c, uint32_t a, uint32_t b) {
  if (!c.o.prior_epipolar || !c.poses[a] || !c.poses[b]) return std::nullopt;
  RelativePose r;
  r.R_ba = c.poses[b]->R_cam_world * c.poses[a]->R_cam_world.transpose();
  r.t_ba = c.poses[b]->t_cam_world - r.R_ba * c.poses[a]->t_cam_world;
  return r;
}

// Clears the inliers of `v` that the LiDAR map contradicts; the pair fails when fewer than min_inliers
// remain. Returns the inliers cleared.
size_t reject_by_lidar(const Context& c, uint32_t a, uint32_t b,
                       const std::vector<std::array<uint32_t, 2>>& mutual, Verification& v) {
  if (c.lidar_depth.empty() || !c.lidar_depth[a] || !c.lidar_depth[b] || !v.verified) return 0;
  auto view = [&](uint32_t image, uint32_t keypoint) {
    return DepthView{c.poses[image]->R_cam_world, c.poses[image]->t_cam_world, c.undistorted[image][keypoint],
                     *c.lidar_depth[image]};
  };
  std::vector<size_t> verified;  // indices into `mutual`
  std::vector<MatchTransfers> transfers;
  for (size_t k = 0; k < mutual.size(); ++k)
    if (v.inlier[k]) {
      verified.push_back(k);
      transfers.push_back(match_transfers(view(a, mutual[k][0]), view(b, mutual[k][1]), c.K));
    }
  // The priors' relative error moves every match of the pair alike: the bound applies to what is left.
  const PairTransferOffset offset = pair_transfer_offset(transfers, c.o.verify.min_inliers);
  size_t rejected = 0;
  for (size_t j = 0; j < verified.size(); ++j)
    if (contradicted_by_lidar(transfers[j], c.o.lidar_check.max_transfer_px, offset.ab, offset.ba)) {
      v.inlier[verified[j]] = 0;
      ++rejected;
    }
  v.inliers -= rejected;
  if (v.inliers < c.o.verify.min_inliers) {
    std::fill(v.inlier.begin(), v.inlier.end(), 0);
    v.inliers = 0;
    v.verified = false;
  }
  return rejected;
}

// Matches and verifies `pairs` on the pool; results in the pairs' order.
void match_pairs(const Context& c, const std::vector<ImagePair>& pairs, std::vector<io::SfmPairMatches>& out,
                 std::vector<PairStats>& stats) {
  const size_t first = out.size();
  out.resize(first + pairs.size());
  stats.resize(first + pairs.size());
  std::mutex progress_mutex;
  size_t done = 0;
  const std::thread::id caller = std::this_thread::get_id();
  parallel_for(pairs.size(), c.o.threads, [&](size_t p) {
    const auto [a, b] = pairs[p];
    const std::optional<RelativePose> prior = relative_prior(c, a, b);
    // With a prior, descriptors are compared only along the prior's epipolar band (guided matching); a
    // learned matcher sees all of both images' keypoints, and the verification below applies the band.
    const auto mutual =
        c.o.match.matcher == Matcher::kLighterGlue
            ? c.o.learned_matcher(c.features[a], c.features[b], c.camera.width, c.camera.height)
        : prior ? match_mutual_among(c.features[a], c.features[b],
                                     prior_candidates(c.undistorted[a], c.undistorted[b], c.K, *prior,
                                                      c.o.verify.prior_epipolar_px),
                                     c.o.match)
                : match_mutual(c.features[a], c.features[b], c.o.match);
    Verification v = verify_pair(c.undistorted[a], c.undistorted[b], mutual, c.K, prior, c.o.verify);
    const size_t rejected_by_lidar = reject_by_lidar(c, a, b, mutual, v);
    io::SfmPairMatches& m = out[first + p];
    m.image_a = a;
    m.image_b = b;
    for (size_t k = 0; k < mutual.size(); ++k)
      m.matches.push_back({mutual[k][0], mutual[k][1], v.inlier[k] != 0});
    stats[first + p] = {a, b, mutual.size(), v.inliers, v.rejected_by_prior, rejected_by_lidar, v.verified};
    std::lock_guard<std::mutex> lock(progress_mutex);
    ++done;
    if (std::this_thread::get_id() == caller) report(c, "matching", done, pairs.size());
  });
  report(c, "matching", pairs.size(), pairs.size());
}

struct Structure {
  TrackSet tracks;
  std::vector<TriangulatedPoint> points;  // per track
};

Structure triangulate_tracks(const Context& c, const std::vector<io::SfmPairMatches>& matches) {
  Structure s;
  std::vector<size_t> counts;
  for (const auto& f : c.features) counts.push_back(f.keypoints.size());
  std::vector<std::vector<io::SfmKeypoint>> keypoints;
  for (const auto& f : c.features) keypoints.push_back(f.keypoints);
  ComponentSplitter split;
  if (c.o.split_conflicts)
    split = [&c](const io::SfmTrack& component, const std::vector<std::array<size_t, 2>>& edges) {
      const ObservationView view = [&c](const io::SfmObservation& o) -> std::optional<TriangulationView> {
        if (!c.poses[o.image]) return std::nullopt;
        const Eigen::Vector2d& px = c.undistorted[o.image][o.keypoint];
        return TriangulationView{c.poses[o.image]->R_cam_world,
                                 c.poses[o.image]->t_cam_world,
                                 {(px.x() - c.K.cx) / c.K.fx, (px.y() - c.K.cy) / c.K.fy}};
      };
      return split_conflicting_component(component, edges, view, c.K.fx, c.K.fy, c.o.conflicts);
    };
  s.tracks = build_tracks(counts, matches, same_location_representatives(keypoints), split);
  s.points.resize(s.tracks.tracks.size());
  parallel_for(s.tracks.tracks.size(), c.o.threads, [&](size_t t) {
    std::vector<TriangulationView> views;
    for (const auto& obs : s.tracks.tracks[t].observations) {
      if (!c.poses[obs.image]) continue;
      const Eigen::Vector2d& px = c.undistorted[obs.image][obs.keypoint];
      views.push_back({c.poses[obs.image]->R_cam_world,
                       c.poses[obs.image]->t_cam_world,
                       {(px.x() - c.K.cx) / c.K.fx, (px.y() - c.K.cy) / c.K.fy}});
    }
    s.points[t] = triangulate(views, c.K.fx, c.K.fy, c.o.triangulation);
    // Indices into `views` back to indices into the track's observations (views skip unposed images).
    std::vector<size_t> posed;
    for (size_t k = 0; k < s.tracks.tracks[t].observations.size(); ++k)
      if (c.poses[s.tracks.tracks[t].observations[k].image]) posed.push_back(k);
    for (size_t& v : s.points[t].views) v = posed[v];
  });
  return s;
}

// Median depth of each image's triangulated points (0: none).
std::vector<double> median_depths(const Context& c, const Structure& s, size_t images) {
  std::vector<std::vector<double>> depths(images);
  for (size_t t = 0; t < s.points.size(); ++t) {
    if (s.points[t].outcome != TriangulationOutcome::kOk) continue;
    for (size_t k : s.points[t].views) {
      const uint32_t i = s.tracks.tracks[t].observations[k].image;
      depths[i].push_back((c.poses[i]->R_cam_world * s.points[t].xyz + c.poses[i]->t_cam_world).z());
    }
  }
  std::vector<double> out(images, 0.0);
  for (size_t i = 0; i < images; ++i) {
    if (depths[i].empty()) continue;
    std::nth_element(depths[i].begin(), depths[i].begin() + depths[i].size() / 2, depths[i].end());
    out[i] = depths[i][depths[i].size() / 2];
  }
  return out;
}

std::vector<ImagePair> select_covisible(const Context& c, const std::vector<uint32_t>& images,
                                        const Structure& first_pass, std::vector<std::string>& notes) {
  std::vector<double> depth = median_depths(c, first_pass, c.features.size());
  std::vector<double> known;
  for (double d : depth)
    if (d > 0) known.push_back(d);
  if (known.empty()) {
    notes.push_back(
        "covisible: the sequential pass triangulated nothing, so no depth: sequential pairs only");
    return {};
  }
  std::nth_element(known.begin(), known.begin() + known.size() / 2, known.end());
  const double fallback = known[known.size() / 2];
  std::vector<PairView> views(c.features.size());
  for (uint32_t i : images) {
    if (!c.poses[i]) continue;
    views[i] = {true, c.poses[i]->R_cam_world, c.poses[i]->t_cam_world, depth[i] > 0 ? depth[i] : fallback};
  }
  return covisible_pairs(images, views, c.K.fx, c.K.fy, c.K.cx, c.K.cy, c.camera.width, c.camera.height,
                         c.o.pairs);
}

void summarize(FrontendResult& r, const Structure& s) {
  FrontendSummary& m = r.summary;
  for (const PairStats& p : r.pairs) {
    ++m.pairs_tried;
    m.pairs_verified += p.accepted;
    m.mutual_matches += p.mutual;
    m.verified_matches += p.verified;
    m.rejected_by_prior += p.rejected_by_prior;
    m.rejected_by_lidar += p.rejected_by_lidar;
  }
  m.inlier_ratio = m.mutual_matches
                       ? static_cast<double>(m.verified_matches) / static_cast<double>(m.mutual_matches)
                       : 0.0;
  m.tracks = s.tracks.tracks.size();
  m.track_conflicts = s.tracks.conflicts;
  m.track_matches = s.tracks.matches;
  m.conflicting_components = s.tracks.conflicting_components;
  m.conflict_keypoints_kept = s.tracks.conflict_observations_kept;
  m.conflict_keypoints_dropped = s.tracks.conflict_observations_dropped;
  double length = 0, error = 0;
  for (const auto& p : r.data.points) {
    length += static_cast<double>(p.observations.size());
    error += p.error_px;
  }
  m.points = r.data.points.size();
  m.mean_track_length = m.points ? length / static_cast<double>(m.points) : 0.0;
  m.mean_error_px = m.points ? error / static_cast<double>(m.points) : 0.0;
  for (const auto& p : s.points) {
    m.rejected_no_angle += p.outcome == TriangulationOutcome::kNoAngle;
    m.rejected_depth += p.outcome == TriangulationOutcome::kBadDepth;
    m.rejected_error += p.outcome == TriangulationOutcome::kLargeError;
    m.rejected_few_views += p.outcome == TriangulationOutcome::kTooFewViews;
  }
}

}  // namespace

void FrontendOptions::check() const {
  preprocess.check();
  features.check();
  if (features.type == FeatureType::kXfeat && !learned_detector)
    throw std::invalid_argument("features xfeat: no learned detector was given (it runs on the device)");
  match.check();
  if (match.matcher == Matcher::kLighterGlue && features.type != FeatureType::kXfeat)
    throw std::invalid_argument("matcher lighterglue: it matches XFeat's descriptors (features xfeat), not " +
                                feature_name(features.type) + "'s");
  if (match.matcher == Matcher::kLighterGlue && !learned_matcher)
    throw std::invalid_argument("matcher lighterglue: no learned matcher was given (it runs on the device)");
  verify.check();
  pairs.check();
  triangulation.check();
  conflicts.check();
  lidar_check.check();
  if (threads < 0) throw std::invalid_argument("threads must be >= 0");
}

FrontendResult run_frontend(const std::filesystem::path& dir, const FrontendOptions& o,
                            const FrontendProgress& progress) {
  o.check();
  const auto t_start = Clock::now();
  FrontendResult r;
  r.options = o;
  FrontendSummary& m = r.summary;
  const bool lidar_check = o.lidar_check.enabled && !o.true_poses;
  io::Scene scene = io::read_scene(dir, {.check_images = true, .load_map = lidar_check});
  if (o.true_poses) {
    if (!scene.gt || scene.gt->poses.empty())
      throw std::invalid_argument(dir.string() + ": true poses asked for, but the scene has no gt/poses.txt");
    scene.poses = scene.gt->poses;
  }
  if (scene.frames.empty()) throw std::invalid_argument(dir.string() + ": the scene has no thermal frames");
  const io::CameraIntrinsics& cam = scene.config.camera;
  OpenCvSingleThread opencv_threads;

  auto t0 = Clock::now();
  const std::vector<PreprocessedFrame> frames = preprocess_frames(dir, scene, o.preprocess);
  m.seconds.preprocess = since(t0);
  m.images = frames.size();

  Context c{o, cam, {cam.fx, cam.fy, cam.cx, cam.cy}, {}, {}, {}, {}, progress};
  const auto poses = io::camera_poses_at_frames(scene);
  for (const auto& T : poses) {
    if (!T) {
      c.poses.emplace_back();
      ++m.without_pose;
      continue;
    }
    const Eigen::Matrix3d R = T->topLeftCorner<3, 3>().transpose();
    c.poses.push_back(Pose{R, -R * T->topRightCorner<3, 1>()});
  }
  if (m.without_pose)
    m.notes.push_back(std::to_string(m.without_pose) +
                      " frames without a prior pose: matched, not triangulated");

  std::vector<uint32_t> kept;
  r.data.images.resize(frames.size());
  for (size_t i = 0; i < frames.size(); ++i) {
    r.data.images[i].frame = scene.frames[i].image.generic_string();
    r.data.images[i].frozen = frames[i].frozen;
    if (frames[i].frozen) {
      ++m.frozen;
      r.frozen_frames.push_back(scene.frames[i].image.filename().string());
    } else {
      kept.push_back(static_cast<uint32_t>(i));
    }
    m.uniform += frames[i].uniform;
  }
  if (m.uniform) m.notes.push_back(std::to_string(m.uniform) + " frames without any contrast: no keypoints");

  t0 = Clock::now();
  c.features.resize(frames.size());
  c.undistorted.resize(frames.size());
  size_t features_done = 0;
  std::mutex progress_mutex;
  const std::thread::id caller = std::this_thread::get_id();
  parallel_for(kept.size(), o.threads, [&](size_t k) {
    const uint32_t i = kept[k];
    c.features[i] = o.features.type == FeatureType::kXfeat ? o.learned_detector(frames[i].image)
                                                           : detect_features(frames[i].image, o.features);
    c.undistorted[i] = undistort_keypoints(cam, c.features[i].keypoints);
    std::lock_guard<std::mutex> lock(progress_mutex);
    ++features_done;
    if (std::this_thread::get_id() == caller) report(c, "features", features_done, kept.size());
  });
  report(c, "features", kept.size(), kept.size());
  if (lidar_check && scene.map && scene.map->size()) {
    c.lidar_depth.resize(frames.size());
    parallel_for(kept.size(), o.threads, [&](size_t k) {
      const uint32_t i = kept[k];
      if (c.poses[i])
        c.lidar_depth[i].emplace(scene.map->positions, c.poses[i]->R_cam_world, c.poses[i]->t_cam_world, c.K,
                                 cam.width, cam.height, o.lidar_check);
    });
    for (const auto& d : c.lidar_depth) m.lidar_checked_images += d.has_value();
  } else if (o.lidar_check.enabled) {
    m.notes.push_back(o.true_poses
                          ? "LiDAR check off: the map is in the odometry's frame, not the true poses'"
                          : "LiDAR check off: the scene has no LiDAR map");
  }
  for (uint32_t i : kept) {
    r.data.images[i].keypoints = c.features[i].keypoints;
    m.keypoints += c.features[i].keypoints.size();
  }
  m.keypoints_per_image =
      kept.empty() ? 0.0 : static_cast<double>(m.keypoints) / static_cast<double>(kept.size());
  m.seconds.features = since(t0);

  std::vector<io::SfmPairMatches> matches;
  if (o.pairs.mode == PairMode::kCovisible) {
    // A sequential pass gives each view a scene depth; covisibility at those depths picks the rest.
    t0 = Clock::now();
    match_pairs(c, sequential_pairs(kept, o.pairs.window), matches, r.pairs);
    const double sequential_matching = since(t0);
    t0 = Clock::now();
    const Structure first = triangulate_tracks(c, matches);
    const std::vector<ImagePair> sequential = sequential_pairs(kept, o.pairs.window);
    std::vector<ImagePair> more;
    for (const ImagePair& p : select_covisible(c, kept, first, m.notes))
      if (std::find(sequential.begin(), sequential.end(), p) == sequential.end()) more.push_back(p);
    m.seconds.pair_selection = since(t0);
    t0 = Clock::now();
    match_pairs(c, more, matches, r.pairs);
    m.seconds.matching = sequential_matching + since(t0);
  } else {
    t0 = Clock::now();
    const std::vector<ImagePair> pairs = o.pairs.mode == PairMode::kSequential
                                             ? sequential_pairs(kept, o.pairs.window)
                                             : exhaustive_pairs(kept);
    m.seconds.pair_selection = since(t0);
    t0 = Clock::now();
    match_pairs(c, pairs, matches, r.pairs);
    m.seconds.matching = since(t0);
  }
  for (auto& p : matches)
    if (!p.matches.empty()) r.data.pairs.push_back(std::move(p));

  t0 = Clock::now();
  const Structure s = triangulate_tracks(c, r.data.pairs);
  m.seconds.triangulation = since(t0);
  r.data.tracks = s.tracks.tracks;
  for (size_t t = 0; t < s.points.size(); ++t) {
    const TriangulatedPoint& p = s.points[t];
    if (p.outcome != TriangulationOutcome::kOk) continue;
    r.data.tracks[t].point = static_cast<int64_t>(r.data.points.size());
    io::SfmPoint point;
    point.xyz = p.xyz;
    point.error_px = p.mean_error_px;
    for (size_t k : p.views) point.observations.push_back(s.tracks.tracks[t].observations[k]);
    r.data.points.push_back(std::move(point));
  }
  summarize(r, s);
  if (scene.gt && !scene.gt->planes.empty() && !r.data.points.empty()) {
    std::vector<double> distances;
    for (const auto& p : r.data.points) {
      double best = INFINITY;
      for (const auto& plane : scene.gt->planes)
        best = std::min(best, std::abs(plane.n.dot(p.xyz) + plane.d));
      distances.push_back(best);
    }
    double sum = 0;
    for (double d : distances) sum += d;
    m.true_plane_mean_m = sum / static_cast<double>(distances.size());
    std::nth_element(distances.begin(), distances.begin() + static_cast<std::ptrdiff_t>(distances.size() / 2),
                     distances.end());
    m.true_plane_median_m = distances[distances.size() / 2];
  }
  m.seconds.total = since(t_start);
  return r;
}

std::string frontend_json(const FrontendResult& r) {
  using nlohmann::json;
  const FrontendSummary& m = r.summary;
  const FrontendOptions& o = r.options;
  json pairs = json::array();
  for (const PairStats& p : r.pairs)
    pairs.push_back(
        {{"image_a", p.image_a},
         {"image_b", p.image_b},
         {"mutual", p.mutual},
         {"verified", p.verified},
         {"rejected_by_prior", p.rejected_by_prior},
         {"rejected_by_lidar", p.rejected_by_lidar},
         {"accepted", p.accepted},
         {"inlier_ratio", p.mutual ? static_cast<double>(p.verified) / static_cast<double>(p.mutual) : 0.0}});
  json j = {
      {"format", "litgs-frontend 1"},
      {"options",
       {{"features", feature_name(o.features.type)},
        {"matcher", matcher_name(o.match.matcher)},
        {"max_keypoints", o.features.max_keypoints},
        {"xfeat_scale", o.features.xfeat_scale},
        {"grid", {o.features.grid_cols, o.features.grid_rows}},
        {"clahe", o.preprocess.clahe},
        {"clahe_clip_limit", o.preprocess.clahe_clip_limit},
        {"clahe_tiles", o.preprocess.clahe_tiles},
        {"stretch_percentiles", {o.preprocess.low_percentile, o.preprocess.high_percentile}},
        {"stretch_window", o.preprocess.stretch_window},
        {"frozen_threshold", o.preprocess.frozen_threshold},
        {"pairs", pairs_name(o.pairs)},
        {"ratio", o.match.ratio},
        {"magsac_threshold_px", o.verify.max_error_px},
        {"prior_epipolar_px", o.prior_epipolar ? json(o.verify.prior_epipolar_px) : json(nullptr)},
        {"min_inliers", o.verify.min_inliers},
        {"lidar_transfer_px", o.lidar_check.enabled ? json(o.lidar_check.max_transfer_px) : json(nullptr)},
        {"triangulation_max_error_px", o.triangulation.max_error_px},
        {"min_angle_deg", o.triangulation.min_angle_deg},
        {"min_views", o.triangulation.min_views},
        {"split_conflicts", o.split_conflicts},
        {"conflict_max_error_px", o.conflicts.max_error_px},
        {"threads", resolve_threads(o.threads)},
        {"poses", o.true_poses ? "gt/poses.txt" : "poses.txt"}}},
      {"summary",
       {{"images", m.images},
        {"frozen", m.frozen},
        {"uniform", m.uniform},
        {"without_pose", m.without_pose},
        {"keypoints", m.keypoints},
        {"keypoints_per_image", m.keypoints_per_image},
        {"pairs_tried", m.pairs_tried},
        {"pairs_verified", m.pairs_verified},
        {"mutual_matches", m.mutual_matches},
        {"verified_matches", m.verified_matches},
        {"rejected_by_prior", m.rejected_by_prior},
        {"rejected_by_lidar", m.rejected_by_lidar},
        {"lidar_checked_images", m.lidar_checked_images},
        {"inlier_ratio", m.inlier_ratio},
        {"tracks", m.tracks},
        {"track_conflicts", m.track_conflicts},
        {"track_matches", m.track_matches},
        {"conflicts",
         {{"split", o.split_conflicts},
          {"components", m.conflicting_components},
          {"keypoints_kept", m.conflict_keypoints_kept},
          {"keypoints_dropped", m.conflict_keypoints_dropped},
          {"lost_match_share",
           m.track_matches ? static_cast<double>(m.track_conflicts) / static_cast<double>(m.track_matches)
                           : 0.0}}},
        {"points", m.points},
        {"mean_track_length", m.mean_track_length},
        {"mean_reprojection_error_px", m.mean_error_px},
        {"true_plane_distance_m", {{"median", m.true_plane_median_m}, {"mean", m.true_plane_mean_m}}},
        {"rejected_tracks",
         {{"no_angle", m.rejected_no_angle},
          {"depth", m.rejected_depth},
          {"reprojection_error", m.rejected_error},
          {"too_few_views", m.rejected_few_views}}},
        {"seconds",
         {{"preprocess", m.seconds.preprocess},
          {"features", m.seconds.features},
          {"pair_selection", m.seconds.pair_selection},
          {"matching", m.seconds.matching},
          {"triangulation", m.seconds.triangulation},
          {"total", m.seconds.total}}},
        {"notes", m.notes}}},
      {"frozen_frames", r.frozen_frames},
      {"pairs", pairs}};
  return j.dump(1);
}

void write_frontend(const std::filesystem::path& scene_dir, const FrontendResult& r) {
  io::write_sfm(scene_dir / "sfm", r.data, frontend_json(r));
}

}  // namespace litgs::host::frontend
