#include "host/refine/scene_refine.h"

#include <fstream>
#include <nlohmann/json.hpp>
#include <sstream>
#include <stdexcept>

#include "host/lidar_map/map_builder.h"
#include "host/refine/ate.h"
#include "host/synth/presets.h"
#include "io/atomic_file.h"
#include "io/pcd.h"
#include "io/scene.h"
#include "io/scene_text.h"
#include "io/sfm_files.h"

namespace litgs::host::refine {
namespace fs = std::filesystem;
namespace {

Eigen::Matrix4d to_matrix(const CameraPose& c) {
  Eigen::Matrix4d T = Eigen::Matrix4d::Identity();
  T.topLeftCorner<3, 3>() = c.q_world_cam.toRotationMatrix();
  T.topRightCorner<3, 1>() = c.p_world_cam;
  return T;
}

CameraPose from_matrix(double t, const Eigen::Matrix4d& T) {
  CameraPose c;
  c.t_s = t;
  c.q_world_cam = Eigen::Quaterniond(Eigen::Matrix3d(T.topLeftCorner<3, 3>())).normalized();
  c.p_world_cam = T.topRightCorner<3, 1>();
  return c;
}

// T_body_cam of the scene's pose frame (identity for camera poses).
Eigen::Matrix4d body_from_camera(const io::SceneConfig& c) {
  if (c.poses_frame == io::PoseFrame::kCamera) return Eigen::Matrix4d::Identity();
  return c.T_imu_lidar * c.T_cam_lidar.inverse();
}

// Camera poses at the frame times; std::invalid_argument naming the file when a frame lies outside it.
std::vector<CameraPose> camera_poses_at(const std::vector<io::TumPose>& poses,
                                        const std::vector<io::SceneFrame>& frames,
                                        const io::SceneConfig& config, const std::string& what) {
  std::vector<CameraPose> out;
  for (const auto& f : frames) {
    // IMU poses run on the LiDAR clock (the convention of export_scene).
    const double t =
        config.poses_frame == io::PoseFrame::kImu ? f.t_s + config.time_offset_cam_lidar_s : f.t_s;
    const auto T = io::tum_pose_at(poses, t, 1e-6);
    if (!T)
      throw std::invalid_argument(what + " has no pose at frame time " + std::to_string(f.t_s) +
                                  " (outside the trajectory, or an unknown rotation)");
    out.push_back(from_matrix(t, *T * body_from_camera(config)));
  }
  return out;
}

std::vector<io::TumPose> to_tum(const std::vector<CameraPose>& poses, const io::SceneConfig& config) {
  const Eigen::Matrix4d T_cam_body = body_from_camera(config).inverse();
  std::vector<CameraPose> body;
  for (const auto& c : poses) body.push_back(from_matrix(c.t_s, to_matrix(c) * T_cam_body));
  return as_tum_poses(body);
}

// "synthetic: litgs-engine synth --preset NAME --seed S ..." -> the preset's world.
synth::World synthetic_world(const io::SceneConfig& config, const fs::path& dir) {
  std::istringstream in(config.source);
  std::string word, preset, appearance = "textured";
  uint64_t seed = 1;
  while (in >> word) {
    if (word == "--preset") in >> preset;
    if (word == "--seed") in >> seed;
    if (word == "--appearance") in >> appearance;
  }
  if (config.source.rfind("synthetic:", 0) != 0 || preset.empty())
    throw std::invalid_argument(
        (dir / "scene.yaml").string() +
        ": --tracks oracle needs a scene made by litgs-engine synth (its source line names "
        "the preset); this one says \"" +
        config.source + "\"");
  synth::World world = synth::make_preset(preset, seed, synth::parse_appearance(appearance)).world;
  world.build_index();
  return world;
}

std::set<size_t> read_frozen(const fs::path& path) {
  std::set<size_t> frozen;
  std::ifstream in(path);
  std::string line;
  while (std::getline(in, line)) {
    if (line.empty() || line[0] == '#') continue;
    std::istringstream s(line);
    double t = 0;
    size_t index = 0;
    if (s >> t >> index) frozen.insert(index);
  }
  return frozen;
}

nlohmann::json stats_json(const ResidualStats& s) {
  return {{"observations", s.observations},
          {"reprojection_rms_px", s.reprojection_rms_px},
          {"behind_camera", s.behind_camera},
          {"reprojection_median_px", s.reprojection_median_px},
          {"plane_points", s.plane_points},
          {"plane_rms_m", s.plane_rms_m},
          {"anchored_observations", s.anchored_observations},
          {"anchored_reprojection_rms_px", s.anchored_reprojection_rms_px}};
}

nlohmann::json report_json(const SceneRefineReport& sr, const SceneRefineOptions& o) {
  const RefineReport& r = sr.refine;
  nlohmann::json rounds = nlohmann::json::array();
  for (const auto& rr : r.rounds)
    rounds.push_back({{"local_windows", rr.local_solves},
                      {"before", stats_json(rr.before)},
                      {"after", stats_json(rr.after)},
                      {"planes",
                       {{"by_depth_image", rr.planes.by_depth_image},
                        {"by_nearest_point", rr.planes.by_nearest_point},
                        {"unassociated", rr.planes.unassociated},
                        {"radius_m", rr.planes.radius_m}}},
                      {"scans",
                       {{"scans", rr.scans.scans},
                        {"map_points", rr.scans.map_points},
                        {"planar_map_points", rr.scans.planar_map_points},
                        {"links", rr.scans.links},
                        {"gate_m", rr.scans.gate_m},
                        {"rms_before_m", rr.scan_rms_before_m},
                        {"rms_after_m", rr.scan_rms_after_m}}},
                      {"rejected_observations", rr.rejected_observations},
                      {"rejected_planes", rr.rejected_planes},
                      {"dropped_points", rr.dropped_points},
                      {"reject_bound_px", rr.reject_bound_px},
                      {"reject_bound_m", rr.reject_bound_m},
                      {"ceres",
                       {{"initial_cost", rr.global.initial_cost},
                        {"final_cost", rr.global.final_cost},
                        {"iterations", rr.global.iterations},
                        {"termination", rr.global.termination},
                        {"usable", rr.global.usable},
                        {"reprojection_residuals", rr.global.reprojection_residuals},
                        {"plane_residuals", rr.global.plane_residuals},
                        {"prior_residuals", rr.global.prior_residuals},
                        {"anchor_residuals", rr.global.anchor_residuals},
                        {"scan_residuals", rr.global.scan_residuals},
                        {"brief", rr.global.brief},
                        {"seconds", rr.global.seconds}}},
                      {"seconds", rr.seconds}});
  double alpha_mean = 0;
  for (double a : r.alphas) alpha_mean += a / static_cast<double>(std::max<size_t>(1, r.alphas.size()));
  nlohmann::json j = {{"status", r.status},
                      {"outcome", r.outcome},
                      {"holdout",
                       {{"tracks", r.holdout.tracks},
                        {"tracks_used", r.holdout.tracks_used},
                        {"observations", r.holdout.observations},
                        {"measured", r.holdout.measured},
                        {"prior_median_px", r.holdout.prior_median_px},
                        {"refined_median_px", r.holdout.refined_median_px},
                        {"keep_refined", r.holdout.keep_refined}}},
                      {"scan_check",
                       {{"scans", sr.scans.scans},
                        {"points", sr.scans.points},
                        {"measured", sr.scans.measured},
                        {"prior_mean_m", sr.scans.prior_mean_m},
                        {"refined_mean_m", sr.scans.refined_mean_m},
                        {"keep_refined", sr.scans.keep_refined}}},
                      {"stopped_early", r.stopped_early},
                      {"frames", r.frames},
                      {"points", r.points},
                      {"observations", r.observations},
                      {"untriangulated_points", r.untriangulated_points},
                      {"frozen_frames", r.frozen_frames},
                      {"weak_frames", r.weak_frames},
                      {"median_frame_observations", r.median_frame_observations},
                      {"fewest_frame_observations", r.fewest_frame_observations},
                      {"frames_without_observations", r.frames_without_observations},
                      {"anchors", r.anchors},
                      {"anchored_tracks", r.anchor_association.anchored_tracks},
                      {"anchors_in_view", r.anchor_association.anchors_in_view},
                      {"ambiguous_anchors", r.anchor_association.ambiguous_anchors},
                      {"guarded_anchor_covariances", r.guarded_anchor_covariances},
                      {"anchor_weight_median_m-3", r.anchor_weight_median_raw},
                      {"alpha_mean", alpha_mean},
                      {"before", stats_json(r.before)},
                      {"after", stats_json(r.after)},
                      {"rounds", rounds},
                      {"seconds", r.seconds},
                      {"notes", r.notes},
                      {"tracks", sr.tracks},
                      {"priors", sr.priors},
                      {"options",
                       {{"rounds", o.refine.rounds},
                        {"anchors", sr.anchors},
                        {"planes", o.refine.use_planes},
                        {"alpha_min", o.refine.weights.alpha_min},
                        {"alpha_max", o.refine.weights.alpha_max},
                        {"window", o.refine.window},
                        {"threads", o.refine.threads},
                        {"holdout_every", o.refine.holdout.every},
                        {"absolute_priors", sr.absolute_priors}}}};
  if (sr.control)
    j["control_points"] = {{"observations", sr.control->observations},
                           {"unmatched_cameras", sr.control->unmatched_cameras},
                           {"median_prior_px", sr.control->median_prior_px},
                           {"median_refined_px", sr.control->median_refined_px}};
  if (sr.tracks == "sfm")
    j["sfm"] = {{"tracks", sr.sfm.tracks},
                {"from_front_end_points", sr.sfm.from_front_end_points},
                {"triangulated_here", sr.sfm.triangulated_here},
                {"untriangulated", sr.sfm.untriangulated}};
  if (sr.has_truth) {
    j["ate_before_m"] = sr.ate_before_m;
    j["ate_after_m"] = sr.ate_after_m;
    if (sr.ate_rejected_m >= 0) j["ate_rejected_m"] = sr.ate_rejected_m;
    j["plane_rms_true_m"] = sr.plane_rms_true_m;
  }
  return j;
}

// The map of the scans the scene's map holds (all but the held-out ones), built through `trajectory` as
// `litgs-engine map` builds it, with its local planes.
PlanarMap map_through(const fs::path& dir, const io::Scene& scene, const LidarPoseAt& trajectory) {
  std::vector<size_t> kept;
  std::vector<double> times;
  for (size_t i = 0; i < scene.scans.size(); ++i)
    if (!io::is_heldout_scan(i, scene.config.lidar_holdout_every)) {
      kept.push_back(i);
      times.push_back(scene.scans[i].t_s);
    }
  LidarMapOptions options;
  options.holdout_every = 0;  // the held-out scans are already left out of `kept`
  LidarMapReport report;
  const io::PointCloud map = build_lidar_map(
      times, [&](size_t j) { return io::read_pcd(dir / scene.scans[kept[j]].file); }, trajectory, options,
      report);
  return fit_planes(map.positions, {});
}

// The scans that enter the solve: every scan the guard's scan check does not hold out, its points in range
// deskewed to its stamp through the priors and evenly subsampled, tied to the frame nearest its stamp by
// the priors' pose of the LiDAR in that frame's camera.
std::vector<RefineScan> scans_tied_to_frames(const fs::path& dir, const io::Scene& scene,
                                             const std::vector<CameraPose>& priors, int heldout_every,
                                             size_t points_per_scan) {
  std::vector<RefineScan> out;
  if (priors.empty()) return out;
  const std::vector<io::TumPose> trajectory = to_tum(priors, scene.config);
  const LidarPoseAt lidar_at = scene_lidar_pose(scene.config, trajectory);
  const LidarMapOptions placing;  // the map's range gate and deskew
  for (size_t i = 0; i < scene.scans.size(); ++i) {
    if (io::is_heldout_scan(i, heldout_every)) continue;
    const double t_lidar = scene.scans[i].t_s;
    const auto T_world_lidar = lidar_at(t_lidar);
    if (!T_world_lidar) continue;  // outside the frames' time span
    const double t_cam = t_lidar - scene.config.time_offset_cam_lidar_s;
    size_t f = 0;
    for (size_t k = 1; k < scene.frames.size(); ++k)
      if (std::abs(scene.frames[k].t_s - t_cam) < std::abs(scene.frames[f].t_s - t_cam)) f = k;
    const PlacedScan placed = place_scan(io::read_pcd(dir / scene.scans[i].file), t_lidar, lidar_at, placing);
    if (placed.world.empty()) continue;
    const Eigen::Isometry3d world_lidar(*T_world_lidar);
    RefineScan scan;
    scan.frame = static_cast<uint32_t>(f);
    scan.T_cam_scan = Eigen::Isometry3d(to_matrix(priors[f]).inverse()) * world_lidar;
    const Eigen::Isometry3d lidar_world = world_lidar.inverse();
    const size_t step = std::max<size_t>(1, placed.world.size() / points_per_scan);
    for (size_t k = 0; k < placed.world.size(); k += step)
      scan.points_lidar.push_back(lidar_world * placed.world[k]);
    out.push_back(std::move(scan));
  }
  return out;
}

// The scans the map left out (or, in a scene that holds none out, every Nth scan) through the prior and
// the refined trajectories, each interpolated at the scan's stamp; refined poses that fit them worse give
// way to the priors. Where the scene holds scans out, each trajectory is judged against the map it builds
// itself from the other scans: a map built through one of them (the scene's, through the odometry) would
// favour it, since a held-out scan placed through the same trajectory shares its local error.
void guard_with_scans(const fs::path& dir, const io::Scene& scene, const std::vector<CameraPose>& priors,
                      const ScanCheckOptions& o, PlanarMap& planar, RefineReport& refine_report,
                      ScanVerdict& verdict, std::vector<CameraPose>& poses) {
  const bool own_holdout = scene.config.lidar_holdout_every > 0;
  const std::vector<io::TumPose> prior_trajectory = to_tum(priors, scene.config),
                                 refined_trajectory = to_tum(poses, scene.config);
  const LidarPoseAt prior_at = scene_lidar_pose(scene.config, prior_trajectory),
                    refined_at = scene_lidar_pose(scene.config, refined_trajectory);
  std::vector<CheckedScan> scans;
  for (size_t i = 0; i < scene.scans.size(); ++i) {
    if (!io::is_heldout_scan(i, own_holdout ? scene.config.lidar_holdout_every : static_cast<int>(o.every)))
      continue;
    const auto prior = prior_at(scene.scans[i].t_s), refined = refined_at(scene.scans[i].t_s);
    if (!prior || !refined) continue;  // outside the frames' time span
    scans.push_back({io::read_pcd(dir / scene.scans[i].file).positions, *prior, *refined});
  }
  if (own_holdout) {
    const PlanarMap prior_map = map_through(dir, scene, prior_at),
                    refined_map = map_through(dir, scene, refined_at);
    verdict = judge_on_scans(prior_map, refined_map, scans, o);
  } else {
    if (planar.points.empty()) planar = fit_planes(scene.map->positions, {});
    verdict = judge_on_scans(planar, planar, scans, o);
  }
  if (!own_holdout)
    refine_report.notes.push_back(
        "the map holds every scan (scene.yaml lidar_holdout_every: 0): the scan check uses every " +
        std::to_string(o.every) +
        "th scan, which the map also holds, against the scene's map, built through the odometry; rebuild it "
        "with `litgs-engine map --force` to hold scans out");
  refine_report.notes.push_back(verdict.summary);
  if (!verdict.keep_refined) {
    refine_report.rejected_poses = poses;
    poses = priors;
    refine_report.outcome = "kept the priors";
    refine_report.status =
        "kept the priors: the refined poses put the held-out LiDAR scans farther from the other scans' "
        "planes "
        "(mean " +
        std::to_string(verdict.refined_mean_m) + " m against " + std::to_string(verdict.prior_mean_m) +
        " m through the priors)";
  }
}

}  // namespace

SceneRefineReport refine_scene(const fs::path& dir, const SceneRefineOptions& o) {
  o.refine.check();
  io::SceneReadOptions ro;
  ro.check_images = false;
  const io::Scene scene = io::read_scene(dir, ro);
  const io::CameraIntrinsics& k = scene.config.camera;
  if (o.priors != "auto" && o.priors != "absolute" && o.priors != "odometry")
    throw std::invalid_argument("refine: priors must be auto, absolute or odometry, not '" + o.priors + "'");
  RefineOptions refine_options = o.refine;
  if (o.anchors != "auto" && o.anchors != "on" && o.anchors != "off")
    throw std::invalid_argument("refine: anchors must be auto, on or off, not '" + o.anchors + "'");
  refine_options.ba.absolute_priors =
      o.priors == "auto" ? scene.config.poses_origin == io::PoseOrigin::kAbsolute : o.priors == "absolute";
  if (o.tracks == "synthetic")
    throw std::invalid_argument(
        "refine: --tracks synthetic is now called oracle (tracks projected from the true poses: an "
        "experiment, not the method)");
  const std::string source = o.tracks == "auto" ? "sfm" : o.tracks;
  RefineInput in;
  in.camera = {k.fx, k.fy, k.cx, k.cy, k.width, k.height};
  const fs::path prior_path = dir / "poses_prior.txt";
  const bool kept = fs::exists(prior_path);
  const std::vector<io::TumPose> prior_tum = kept ? io::read_tum(prior_path) : scene.poses;
  in.priors =
      camera_poses_at(prior_tum, scene.frames, scene.config, kept ? prior_path.string() : "poses.txt");
  for (const auto& a : scene.anchors) in.anchors.push_back({a.p_world, a.cov_m2});

  SceneRefineReport report;
  if (o.control_points_csv.empty() != o.markers_xml.empty())
    throw std::invalid_argument("refine: control points need both the CSV and the markers' XML");
  // Read first: a bad file stops before anything is written.
  std::vector<io::ControlPoint> control_points;
  std::optional<io::MetashapeDocument> markers;
  if (!o.control_points_csv.empty()) {
    control_points = io::read_control_points_csv(o.control_points_csv);
    markers = io::read_metashape_xml(o.markers_xml);
  }
  std::vector<CameraPose> truth;
  if (scene.gt && scene.gt->poses.size() >= 3) {
    truth = camera_poses_at(scene.gt->poses, scene.frames, scene.config, "gt/poses.txt");
    report.has_truth = true;
  }
  report.tracks = source;
  refine_options.use_anchors = o.anchors == "on" || (o.anchors == "auto" && source == "oracle");
  report.anchors = refine_options.use_anchors;
  report.absolute_priors = refine_options.ba.absolute_priors;
  report.priors = std::string(refine_options.ba.absolute_priors ? "absolute" : "odometry") +
                  (o.priors == "auto" ? " (scene.yaml poses_origin)" : " (asked for)");
  if (source == "sfm") {
    if (!io::has_sfm(dir / "sfm"))
      throw std::invalid_argument((dir / "sfm").string() +
                                  ": no front-end tracks here (run litgs-engine match SCENE first)");
    in.points = sfm_tracks(io::read_sfm(dir / "sfm"), k, in.priors, &report.sfm);
  } else if (source == "oracle") {
    if (truth.empty())
      throw std::invalid_argument(dir.string() +
                                  ": --tracks oracle needs gt/poses.txt (tracks projected from the truth)");
    const synth::World world = synthetic_world(scene.config, dir);
    std::vector<Eigen::Vector3d> anchors_true;
    if (fs::exists(dir / "gt/anchors.txt"))
      for (const auto& a : io::read_anchors(dir / "gt/anchors.txt")) anchors_true.push_back(a.p_world);
    SyntheticTrackOptions so = o.synthetic;
    if (fs::exists(dir / "gt/frozen.txt")) so.frozen_frames = read_frozen(dir / "gt/frozen.txt");
    in.points = synthetic_tracks(world, truth, in.priors, in.camera, anchors_true, so);
  } else {
    throw std::invalid_argument("refine: unknown track source '" + o.tracks + "' (auto, sfm, oracle)");
  }
  PlanarMap planar;
  if (scene.map && o.refine.use_planes) {
    planar = fit_planes(scene.map->positions, {});
    in.map = &planar;
  }
  if (o.refine.use_scans && !scene.scans.empty()) {
    const int guard_every = scene.config.lidar_holdout_every > 0 ? scene.config.lidar_holdout_every
                                                                 : static_cast<int>(o.scan_check.every);
    in.scans =
        scans_tied_to_frames(dir, scene, in.priors, guard_every, o.refine.scan_alignment.map_points_per_scan);
  }
  std::vector<CameraPose> poses = in.priors;
  // The points as they came (through the priors), written instead of the solve's when the priors are kept:
  // points adjusted to turned-down poses would not fit the poses written beside them.
  const std::vector<TrackPoint> points_through_priors = in.points;
  report.refine = refine(in, poses, refine_options);
  if (report.refine.outcome == "refined" && o.scan_check.every > 0 && scene.map && !scene.scans.empty())
    guard_with_scans(dir, scene, in.priors, o.scan_check, planar, report.refine, report.scans, poses);

  if (markers)
    report.control = control_point_errors(*markers, control_points, scene.config.world_offset_m, in.camera,
                                          in.priors, poses);
  if (report.has_truth) {
    report.ate_before_m =
        absolute_trajectory_error(to_tum(in.priors, {}), to_tum(truth, {}), AteAlignment::kSE3).rmse_m;
    report.ate_after_m =
        absolute_trajectory_error(to_tum(poses, {}), to_tum(truth, {}), AteAlignment::kSE3).rmse_m;
    if (!report.refine.rejected_poses.empty())
      report.ate_rejected_m = absolute_trajectory_error(to_tum(report.refine.rejected_poses, {}),
                                                        to_tum(truth, {}), AteAlignment::kSE3)
                                  .rmse_m;
    if (!scene.gt->planes.empty()) {
      double sum2 = 0;
      size_t count = 0;
      for (const auto& p : in.points) {
        if (!p.active || !p.has_plane) continue;
        double best = std::numeric_limits<double>::infinity();
        for (const auto& g : scene.gt->planes)
          if (std::abs(g.n.dot(p.plane.n)) > 0.9) best = std::min(best, std::abs(g.n.dot(p.X) + g.d));
        if (std::isfinite(best)) {
          sum2 += best * best;
          ++count;
        }
      }
      if (count) report.plane_rms_true_m = std::sqrt(sum2 / static_cast<double>(count));
    }
  }
  // Outputs: the input kept first, so that nothing is lost if a later write fails.
  if (!kept) io::write_tum(prior_path, scene.poses);
  io::PointCloud cloud;
  io::ScalarField anchor{"anchor", {}}, on_plane{"on_plane", {}}, observations{"observations", {}};
  const bool refined = report.refine.outcome == "refined";
  for (const auto& p : refined ? in.points : points_through_priors) {
    if (!p.active) continue;
    cloud.positions.push_back(p.X);
    anchor.values.push_back(p.anchor);
    on_plane.values.push_back(p.has_plane);
    observations.values.push_back(static_cast<double>(p.active_observations()));
  }
  cloud.extra = {anchor, on_plane, observations};
  fs::create_directories(dir / "refine");
  io::PcdWriteOptions pw;
  pw.double_positions = true;
  io::write_pcd(dir / "refine/points.pcd", cloud, pw);
  report.points_written = cloud.size();
  io::write_tum(dir / "poses.txt", to_tum(poses, scene.config));
  io::write_file_atomic(dir / "refine.json",
                        [&](std::ostream& out) { out << report_json(report, o).dump(2) << "\n"; });
  return report;
}

}  // namespace litgs::host::refine
