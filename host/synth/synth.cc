#include "host/synth/synth.h"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <future>
#include <set>
#include <sstream>
#include <stdexcept>
#include <thread>

#include "host/synth/level_drift.h"
#include "host/synth/m2dgr_rig.h"
#include "host/synth/presets.h"
#include "io/atomic_file.h"
#include "io/scene.h"
#include "io/scene_text.h"
#include "io/text.h"

namespace litgs::host::synth {
namespace fs = std::filesystem;
namespace {

// Frame stamps start at a Unix-epoch-like time, as real recordings do.
constexpr double kTimeOrigin_s = 1700000000.0;
// The first frame comes this long after the trajectory starts, so IMU samples precede it.
constexpr double kLeadIn_s = 0.5;

// The files and folders a scene consists of: --force removes these, nothing else.
const std::vector<std::string> kSceneEntries = {"scene.yaml", "thermal", "thermal8",    "poses.txt",
                                                "lidar",      "imu.csv", "anchors.txt", "gt"};

// The frames that the NUC freezes: runs of 1..length_max frames, the first at [first_min, first_max], then
// every [interval_min, interval_max] frames.
std::set<int> nuc_frozen_frames(int frames, const NucOptions& o, Rng& rng) {
  std::set<int> frozen;
  for (int f = rng.uniform_int(o.first_min, o.first_max); f < frames;
       f += rng.uniform_int(o.interval_min, o.interval_max)) {
    const int len = rng.uniform_int(1, o.length_max);
    for (int k = 0; k < len && f + k < frames; ++k) frozen.insert(f + k);
  }
  return frozen;
}

io::TumPose to_tum(double t_s, const Eigen::Isometry3d& T) {
  io::TumPose p;
  p.t_s = t_s;
  p.p_world = T.translation();
  p.q_world_body = Eigen::Quaterniond(T.linear()).normalized();
  return p;
}

template <class F>
void parallel_for(int n, int threads, F&& f) {
  std::vector<std::thread> pool;
  for (int w = 1; w < threads; ++w)
    pool.emplace_back([&, w] {
      for (int i = w; i < n; i += threads) f(i);
    });
  for (int i = 0; i < n; i += threads) f(i);
  for (auto& t : pool) t.join();
}

}  // namespace

std::string SynthOptions::check() const {
  const auto names = preset_names();
  if (std::find(names.begin(), names.end(), preset) == names.end()) {
    std::string list;
    for (const auto& n : names) list += (list.empty() ? "" : ", ") + n;
    return "preset: unknown preset '" + preset + "' (known: " + list + ")";
  }
  if (frames && (*frames < 1 || *frames > 100000))
    return "frames: must be in [1, 100000], got " + std::to_string(*frames);
  if (frame_rate_hz && !(*frame_rate_hz >= 1 && *frame_rate_hz <= 200))
    return "frame_rate_hz: must be in [1, 200], got " + std::to_string(*frame_rate_hz);
  if (width.has_value() != height.has_value()) return "width/height: give both or neither";
  if (lidar_holdout_every < 0 || lidar_holdout_every == 1)
    return "lidar_holdout_every: must be 0 (none) or >= 2, got " + std::to_string(lidar_holdout_every);
  if (width && (*width < 16 || *width > 8192))
    return "width: must be in [16, 8192], got " + std::to_string(*width);
  if (height && (*height < 16 || *height > 8192))
    return "height: must be in [16, 8192], got " + std::to_string(*height);
  if (out.empty()) return "out: no output directory given";
  if (threads < 0 || threads > 64) return "threads: must be in [0, 64]";
  if (appearance != "textured" && appearance != "flat")
    return "appearance: must be textured or flat, got '" + appearance + "'";
  if (!(sensor_noise > 0 && sensor_noise <= 100))
    return "sensor_noise: must be in (0, 100], got " + std::to_string(sensor_noise);
  if (range_noise_m && !(*range_noise_m >= 0 && *range_noise_m < 1))
    return "range_noise_m: must be in [0, 1) metres, got " + std::to_string(*range_noise_m);
  return "";
}

void prepare_synth_output(const fs::path& out, bool force, const std::vector<std::string>& entries,
                          const std::string& what_force_replaces) {
  if (fs::exists(out) && !fs::is_directory(out))
    throw std::invalid_argument("synth: --out " + out.string() + " exists and is not a directory");
  if (fs::is_directory(out) && !fs::is_empty(out)) {
    if (!force)
      throw std::invalid_argument("synth: --out " + out.string() +
                                  " exists and is not empty (use --force to replace " + what_force_replaces +
                                  ")");
    for (const std::string& name : entries) fs::remove_all(out / name);
  }
  fs::create_directories(out);
}

int resolve_synth_threads(int requested) {
  return requested > 0 ? requested : std::clamp(static_cast<int>(std::thread::hardware_concurrency()), 1, 8);
}

SynthReport generate_synthetic_scene(const SynthOptions& options) {
  const auto start = std::chrono::steady_clock::now();
  if (const std::string problem = options.check(); !problem.empty())
    throw std::invalid_argument("synth: " + problem);
  if (options.sensor_noise != 1 || options.range_noise_m)
    throw std::invalid_argument(
        "synth: --sensor-noise and --range-noise apply to the calibration sets "
        "(circle-grid, holed-board), not to --preset " +
        options.preset);
  Preset p = make_preset(options.preset, options.seed, parse_appearance(options.appearance));
  if (options.frame_rate_hz) {  // the same stretch of the world, sampled more or less densely
    p.max_frames = static_cast<int>(std::floor(p.max_frames * *options.frame_rate_hz / p.frame_rate_hz));
    p.frames = static_cast<int>(std::lround(p.frames * *options.frame_rate_hz / p.frame_rate_hz));
    p.frame_rate_hz = *options.frame_rate_hz;
  }
  if (options.frames) {
    std::ostringstream hz;
    hz << p.frame_rate_hz;
    if (*options.frames > p.max_frames)
      throw std::invalid_argument("synth: frames: preset " + p.name + " covers at most " +
                                  std::to_string(p.max_frames) + " frames at " + hz.str() +
                                  " Hz (the rig would leave its world), got " +
                                  std::to_string(*options.frames));
    p.frames = *options.frames;
  }
  if (!options.rig.empty()) {
    apply_m2dgr_rig({options.rig, options.rig_camera_block, options.rig_imu_block}, options.width,
                    options.height, p);
  } else if (options.width) {
    p.camera.width = *options.width;
    p.camera.height = *options.height;
  }
  for (const auto& [what, problem] : {std::pair{"camera", p.camera.check()},
                                      {"lidar", p.lidar.check()},
                                      {"imu", p.imu.check()},
                                      {"estimator", p.estimator.check()},
                                      {"nuc", p.nuc.check()},
                                      {"trajectory", p.trajectory.check()}})
    if (!problem.empty()) throw std::invalid_argument(std::string("synth: preset ") + what + "." + problem);
  const int threads = resolve_synth_threads(options.threads);
  prepare_synth_output(options.out, options.force, kSceneEntries, "the scene files in it");

  const Trajectory trajectory(p.trajectory);
  const io::CameraIntrinsics K = p.camera.intrinsics();
  const int n = p.frames;
  std::vector<double> t_traj(n), distance(n);
  std::vector<Eigen::Isometry3d> T_world_cam(n), T_world_lidar(n);
  io::Scene scene;
  scene.gt.emplace();
  for (int i = 0; i < n; ++i) {
    t_traj[i] = kLeadIn_s + i / p.frame_rate_hz;
    const TrajectoryState s = trajectory.at(t_traj[i]);
    distance[i] = s.distance_m;
    T_world_cam[i] = s.T_world_body() * p.T_imu_cam;
    T_world_lidar[i] = s.T_world_body() * p.T_imu_lidar;
    const double t = kTimeOrigin_s + t_traj[i];
    scene.frames.push_back({t, {}});
    scene.scans.push_back({t, {}});
    scene.gt->poses.push_back(to_tum(t, T_world_cam[i]));
  }
  Rng pose_rng(options.seed, Stream::kPoses);
  scene.poses = drift_poses(scene.gt->poses, distance, p.estimator, pose_rng);

  // LiDAR: each scan from its own stream, so threads change nothing.
  std::vector<LidarScan> scans(n);
  parallel_for(n, threads, [&](int i) {
    Rng rng(options.seed, Stream::kLidar, static_cast<uint64_t>(i));
    scans[i] = simulate_lidar_scan(p.world, T_world_lidar[i], scene.frames[i].t_s, t_traj[i], p.lidar, rng);
  });
  // The map leaves scans 0, N, 2N, ... out, as `litgs-engine map` does, so that refine's scan check meets
  // scans the map never held; the true map is the same returns without noise.
  const int holdout_every = options.lidar_holdout_every > 0 && n >= 2 * options.lidar_holdout_every
                                ? options.lidar_holdout_every
                                : 0;
  LidarMaps maps = accumulate_lidar_map(scans, T_world_lidar, p.map_voxel_m, holdout_every);
  scene.map = std::move(maps.noisy);
  scene.gt->map = std::move(maps.truth);
  scene.gt->planes = p.world.planes();

  std::vector<std::vector<io::Anchor>> anchors(n);
  std::vector<std::vector<Eigen::Vector3d>> anchor_truth(n);
  parallel_for(n, threads, [&](int i) {
    Rng rng(options.seed, Stream::kAnchors, static_cast<uint64_t>(i));
    anchors[i] = pick_anchors(p.world, K, T_world_cam[i], p.estimator, rng, anchor_truth[i]);
  });
  std::vector<io::Anchor> true_anchors;
  for (int i = 0; i < n; ++i)
    for (size_t k = 0; k < anchors[i].size(); ++k) {
      scene.anchors.push_back(anchors[i][k]);
      true_anchors.push_back({anchor_truth[i][k], anchors[i][k].cov_m2});
    }

  Rng imu_rng(options.seed, Stream::kImu);
  ImuBias bias;
  scene.imu = simulate_imu(trajectory, kTimeOrigin_s, 0, t_traj.back() + kLeadIn_s, p.imu, imu_rng, bias);

  Rng nuc_rng(options.seed, Stream::kNuc);
  const std::set<int> frozen = nuc_frozen_frames(n, p.nuc, nuc_rng);

  io::SceneConfig& c = scene.config;
  c.camera = K;
  c.T_cam_lidar = (p.T_imu_cam.inverse() * p.T_imu_lidar).matrix();
  c.T_imu_lidar = p.T_imu_lidar.matrix();
  c.poses_frame = io::PoseFrame::kCamera;
  c.has_lidar_map = true;
  c.lidar_holdout_every = holdout_every;
  std::ostringstream source;
  source << "synthetic: litgs-engine synth --preset " << p.name << " --seed " << options.seed << " --frames "
         << n << " --width " << K.width << " --height " << K.height << (options.drift ? " --drift" : "")
         << (options.appearance != "textured" ? " --appearance " + options.appearance : "")
         << (options.rig.empty() ? "" : " --rig " + options.rig.filename().string()) << " (" << p.description
         << ")";
  c.source = source.str();

  // Ground truth that the io reader does not know: written first, scene.yaml still comes last.
  const fs::path out = options.out;
  fs::create_directories(out / "gt");
  io::write_anchors(out / "gt/anchors.txt", true_anchors);
  io::write_file_atomic(out / "gt/frozen.txt", [&](std::ostream& os) {
    os << "# frames that repeat the previous frame exactly (non-uniformity correction): timestamp, frame "
          "index\n";
    for (const int f : frozen) os << io::format_double(scene.frames[f].t_s) << " " << f << "\n";
  });
  io::write_file_atomic(out / "gt/imu_bias.txt", [&](std::ostream& os) {
    os << "# constant IMU biases, IMU frame: gyro_x gyro_y gyro_z (rad/s) accel_x accel_y accel_z (m/s^2)\n";
    for (int k = 0; k < 3; ++k) os << io::format_double(bias.gyro_rad_s[k]) << " ";
    for (int k = 0; k < 3; ++k) os << io::format_double(bias.accel_m_s2[k]) << (k < 2 ? " " : "\n");
  });

  // True depth of every frame at its true pose (eval's co-visibility mask).
  fs::create_directories(out / "gt/depth");
  for (size_t i = 0; i < scene.frames.size(); ++i)
    io::write_image(out / "gt/depth" / io::frame_file_name(scene.frames[i].t_s).filename(),
                    true_depth_mm(p.world, K, T_world_cam[i]));

  // Frames are rendered as write_scene asks for them (a frozen frame repeats its source frame). While
  // write_scene encodes frame i, the next source frame renders and frame i's 8-bit view is written beside
  // it; every frame is a pure function of its index, so this overlap changes no byte.
  fs::create_directories(out / "thermal8");
  auto source_of = [&](size_t i) {
    int f = static_cast<int>(i);
    while (f > 0 && frozen.count(f)) --f;
    return f;
  };
  // The level drift (SynthOptions::drift): a frozen frame repeats its source frame's bytes, drift included.
  std::vector<LevelDrift> drift;
  if (options.drift) {
    std::vector<double> times;
    for (const auto& f : scene.frames) times.push_back(f.t_s);
    size_t first_after_freeze = times.size();
    if (!frozen.empty()) {
      int f = *frozen.begin();
      while (frozen.count(f)) ++f;
      first_after_freeze = static_cast<size_t>(f);
    }
    drift = level_drift(times, first_after_freeze);
    for (const int f : frozen) drift[static_cast<size_t>(f)] = drift[static_cast<size_t>(source_of(f))];
    write_level_drift(out / "gt/levels.txt", times, drift);
  }
  auto render = [&](int f) {
    io::Image raw =
        render_thermal(p.world, p.camera, T_world_cam[f], options.seed, static_cast<uint64_t>(f), threads);
    if (!drift.empty()) apply_level_drift(raw, drift[static_cast<size_t>(f)]);
    return raw;
  };
  io::Image current;
  int current_source = -1, next_source = -1;
  std::future<io::Image> next;
  std::future<void> writing8;
  auto frame_image = [&](size_t i) {
    const int src = source_of(i);
    if (src != current_source) {
      if (next.valid()) {
        io::Image prefetched = next.get();
        current = next_source == src ? std::move(prefetched) : render(src);
      } else {
        current = render(src);
      }
      current_source = src;
    }
    if (i + 1 < static_cast<size_t>(n) && !next.valid() && source_of(i + 1) != src) {
      next_source = source_of(i + 1);
      next = std::async(std::launch::async, render, next_source);
    }
    if (writing8.valid()) writing8.get();  // rethrows a failed write
    const fs::path path8 = out / "thermal8" / io::frame_file_name(scene.frames[i].t_s).filename();
    auto write8 = [&p, path8](io::Image raw) { io::write_image(path8, auto_gain_8bit(raw, p.camera)); };
    if (i + 1 < static_cast<size_t>(n))
      writing8 = std::async(std::launch::async, write8, current);
    else
      write8(current);  // the last one before scene.yaml: nothing may still be in flight then
    return current;
  };
  auto scan_cloud = [&](size_t i) {
    io::PointCloud cloud;
    cloud.positions = scans[i].points_lidar;
    return cloud;
  };
  io::write_scene(out, scene, frame_image, scan_cloud);

  SynthReport r;
  r.preset = p.name;
  r.frames = n;
  r.frozen_frames = static_cast<int>(frozen.size());
  for (const auto& s : scans) r.scan_points += s.points_lidar.size();
  r.map_points = scene.map->size();
  r.anchors = scene.anchors.size();
  r.imu_samples = scene.imu.size();
  r.planes = scene.gt->planes.size();
  r.path_length_m = distance.back() - distance.front();
  r.final_drift_m = (scene.poses.back().p_world - scene.gt->poses.back().p_world).norm();
  r.seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  return r;
}

}  // namespace litgs::host::synth
