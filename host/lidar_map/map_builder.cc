#include "host/lidar_map/map_builder.h"

#include <Eigen/Geometry>
#include <algorithm>
#include <chrono>
#include <cmath>
#include <fstream>
#include <limits>
#include <stdexcept>
#include <unordered_map>

#include "io/pcd.h"
#include "io/scene_yaml.h"

namespace litgs::host {
namespace {

// Per voxel: the sums that give its centroid and mean intensity.
struct VoxelSum {
  Eigen::Vector3d xyz = Eigen::Vector3d::Zero();
  double intensity = 0;
  uint32_t count = 0;
};

// Poses sampled across one scan's time span; a point's pose interpolates the two around its time.
struct ScanMotion {
  double t0 = 0, dt = 0;
  std::vector<Eigen::Quaterniond> q;
  std::vector<Eigen::Vector3d> p;

  Eigen::Vector3d place(const Eigen::Vector3d& x, double t) const {
    if (q.size() == 1 || dt <= 0) return q[0] * x + p[0];
    const double s = std::clamp((t - t0) / dt, 0.0, static_cast<double>(q.size() - 1));
    const size_t i = std::min(static_cast<size_t>(s), q.size() - 2);
    const double f = s - static_cast<double>(i);
    return q[i].slerp(f, q[i + 1]) * x + (1 - f) * p[i] + f * p[i + 1];
  }
};

void add_pose(ScanMotion& m, const Eigen::Matrix4d& T) {
  m.q.emplace_back(Eigen::Matrix3d(T.topLeftCorner<3, 3>()));
  m.p.push_back(T.topRightCorner<3, 1>());
}

// 21 bits per axis (offset binary): +-1,048,576 voxels, 100 km at 0.1 m.
constexpr int64_t kVoxelHalfRange = int64_t{1} << 20;

}  // namespace

uint64_t voxel_key(const Eigen::Vector3d& p, double voxel_m) {
  uint64_t key = 0;
  for (int a = 0; a < 3; ++a) {
    const double c = std::floor(p[a] / voxel_m);
    if (!(std::abs(c) < static_cast<double>(kVoxelHalfRange)))
      throw std::invalid_argument("LiDAR map: a point at " + std::to_string(p[a]) + " m lies beyond the " +
                                  std::to_string(kVoxelHalfRange) + " voxels of the map's grid (voxel " +
                                  std::to_string(voxel_m) + " m)");
    key = (key << 21) | static_cast<uint64_t>(static_cast<int64_t>(c) + kVoxelHalfRange);
  }
  return key;
}

void LidarMapOptions::check() const {
  if (!(voxel_m > 0)) throw std::invalid_argument("LidarMapOptions.voxel_m must be > 0");
  if (!(min_range_m >= 0) || !(max_range_m > min_range_m))
    throw std::invalid_argument("LidarMapOptions: need 0 <= min_range_m < max_range_m");
  if (deskew_samples < 2) throw std::invalid_argument("LidarMapOptions.deskew_samples must be >= 2");
  if (holdout_every < 0 || holdout_every == 1)
    throw std::invalid_argument("LidarMapOptions.holdout_every must be 0 (none) or >= 2");
  planes.check();
}

LidarPoseAt scene_lidar_pose(const io::Scene& scene) {
  return scene_lidar_pose(scene.config, scene.poses);
}

LidarPoseAt scene_lidar_pose(const io::SceneConfig& config, const std::vector<io::TumPose>& trajectory) {
  const Eigen::Matrix4d T_body_lidar =
      config.poses_frame == io::PoseFrame::kCamera ? config.T_cam_lidar : config.T_imu_lidar;
  // Camera poses run on the camera clock, IMU poses on the LiDAR's (the convention of export_scene).
  const double offset = config.poses_frame == io::PoseFrame::kCamera ? config.time_offset_cam_lidar_s : 0.0;
  const std::vector<io::TumPose>* poses = &trajectory;
  return [poses, T_body_lidar, offset](double t_lidar) -> std::optional<Eigen::Matrix4d> {
    const auto T = io::tum_pose_at(*poses, t_lidar - offset, 1e-6);
    if (!T) return std::nullopt;
    return Eigen::Matrix4d(*T * T_body_lidar);
  };
}

PlacedScan place_scan(const io::PointCloud& cloud, double t_stamp_s, const LidarPoseAt& pose_at,
                      const LidarMapOptions& o) {
  PlacedScan out;
  const auto T0 = pose_at(t_stamp_s);
  if (!T0) return out;
  const io::ScalarField* time = o.deskew ? cloud.field("time") : nullptr;
  ScanMotion motion;
  if (time && !time->values.empty()) {
    const auto [lo, hi] = std::minmax_element(time->values.begin(), time->values.end());
    motion.t0 = *lo;
    motion.dt = (*hi - *lo) / (o.deskew_samples - 1);
    for (int k = 0; k < o.deskew_samples; ++k) {
      // Beyond the trajectory's ends the scan's own stamp pose stands in.
      const auto T = pose_at(t_stamp_s + motion.t0 + k * motion.dt);
      add_pose(motion, T ? *T : *T0);
    }
    out.deskewed = true;
  } else {
    add_pose(motion, *T0);
    time = nullptr;
  }
  const double min2 = o.min_range_m * o.min_range_m, max2 = o.max_range_m * o.max_range_m;
  for (size_t i = 0; i < cloud.size(); ++i) {
    const Eigen::Vector3d& x = cloud.positions[i];
    const double r2 = x.squaredNorm();
    if (r2 < min2 || r2 > max2) continue;
    out.world.push_back(motion.place(x, time ? time->values[i] : 0.0));
    out.index.push_back(i);
  }
  return out;
}

io::PointCloud build_lidar_map(const std::vector<double>& times,
                               const std::function<io::PointCloud(size_t)>& scan, const LidarPoseAt& pose_at,
                               const LidarMapOptions& o, LidarMapReport& report) {
  o.check();
  const auto start = std::chrono::steady_clock::now();
  std::unordered_map<uint64_t, VoxelSum> voxels;
  bool all_intensity = true;
  for (size_t s = 0; s < times.size(); ++s) {
    if (!pose_at(times[s])) {
      ++report.scans_without_pose;
      continue;
    }
    const io::PointCloud cloud = scan(s);
    const PlacedScan placed = place_scan(cloud, times[s], pose_at, o);
    report.scans_deskewed += placed.deskewed;
    ++report.scans;
    all_intensity = all_intensity && cloud.intensity.size() == cloud.size();
    for (size_t k = 0; k < placed.world.size(); ++k) {
      const Eigen::Vector3d& w = placed.world[k];
      VoxelSum& v = voxels[voxel_key(w, o.voxel_m)];
      v.xyz += w;
      const size_t i = placed.index[k];
      if (i < cloud.intensity.size()) v.intensity += cloud.intensity[i];
      ++v.count;
      ++report.input_points;
    }
  }
  std::vector<std::pair<uint64_t, const VoxelSum*>> order;
  order.reserve(voxels.size());
  for (const auto& [key, v] : voxels) order.emplace_back(key, &v);
  std::sort(order.begin(), order.end(), [](const auto& a, const auto& b) { return a.first < b.first; });

  io::PointCloud map;
  map.positions.reserve(order.size());
  for (const auto& [key, v] : order) {
    map.positions.push_back(v->xyz / v->count);
    if (all_intensity) map.intensity.push_back(static_cast<float>(v->intensity / v->count));
  }
  voxels.clear();
  const PlanarMap planes = fit_planes(map.positions, o.planes);
  map.normals.assign(map.size(), Eigen::Vector3f::Zero());
  io::ScalarField planarity{"planarity", std::vector<double>(map.size(), 0.0)};
  for (size_t i = 0; i < map.size(); ++i) {
    if (planes.planar[i]) map.normals[i] = planes.normals[i];
    if (std::isfinite(planes.flatness[i])) planarity.values[i] = 1.0 - planes.flatness[i];
  }
  map.extra.push_back(std::move(planarity));
  report.map_points = map.size();
  report.planar_points = planes.planar_count();
  report.seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  report.peak_rss_mb = peak_rss_mb();
  if (report.scans_deskewed < report.scans)
    report.notes.push_back(std::to_string(report.scans - report.scans_deskewed) +
                           " scans have no per-point time: placed with the pose at their stamp");
  if (report.scans_without_pose > 0)
    report.notes.push_back(std::to_string(report.scans_without_pose) +
                           " scans lie outside the trajectory: skipped");
  return map;
}

LidarMapReport write_scene_lidar_map(const std::filesystem::path& dir, const LidarMapOptions& o,
                                     const std::filesystem::path& out, bool replace) {
  io::SceneReadOptions ro;
  ro.check_images = false;
  ro.load_map = false;
  const io::Scene scene = io::read_scene(dir, ro);
  if (scene.scans.empty())
    throw std::invalid_argument(dir.string() +
                                ": the scene has no LiDAR scans (lidar/scans/) to build a map from");
  const std::filesystem::path target = out.empty() ? dir / "lidar" / "map.pcd" : out;
  if (out.empty() && scene.config.has_lidar_map && !replace)
    throw std::invalid_argument(target.string() +
                                " already exists: pass --force to replace it, or --out to write elsewhere");
  const int every = o.holdout_every > 0 && scene.scans.size() >= 2 * static_cast<size_t>(o.holdout_every)
                        ? o.holdout_every
                        : 0;
  std::vector<size_t> kept, heldout;
  for (size_t i = 0; i < scene.scans.size(); ++i)
    (io::is_heldout_scan(i, every) ? heldout : kept).push_back(i);
  auto build = [&](const std::vector<size_t>& indices, LidarMapReport& report) {
    std::vector<double> times;
    for (size_t i : indices) times.push_back(scene.scans[i].t_s);
    return build_lidar_map(
        times, [&](size_t k) { return io::read_pcd(dir / scene.scans[indices[k]].file, {true}); },
        scene_lidar_pose(scene), o, report);
  };
  LidarMapReport report;
  const io::PointCloud map = build(kept, report);
  if (report.scans == 0)
    throw std::invalid_argument(dir.string() + ": none of the " + std::to_string(kept.size()) +
                                " LiDAR scans for the map lies within the trajectory of poses.txt");
  io::PcdWriteOptions wo;
  wo.double_positions = true;
  const std::filesystem::path heldout_target =
      out.empty() ? dir / io::kHeldoutScansMap
                  : target.parent_path() / (target.stem().string() + ".heldout.pcd");
  io::PointCloud held_map;
  if (!heldout.empty()) {
    LidarMapReport held;
    held_map = build(heldout, held);
    report.scans_heldout = held.scans;
    report.heldout_points = held_map.size();
  } else if (o.holdout_every > 0) {
    report.notes.push_back("no scan held out: " + std::to_string(scene.scans.size()) +
                           " scans are fewer than 2 x holdout_every (" + std::to_string(o.holdout_every) +
                           "); geometry will be measured against the training map itself");
  }
  io::write_pcd(target, map, wo);
  std::error_code ignored;
  std::filesystem::remove(heldout_target, ignored);  // a stale one would pair with the wrong map
  if (report.scans_heldout > 0) io::write_pcd(heldout_target, held_map, wo);
  if (out.empty()) {
    io::SceneConfig config = scene.config;
    config.has_lidar_map = true;
    config.lidar_holdout_every = report.scans_heldout > 0 ? every : 0;
    if (config.has_lidar_map != scene.config.has_lidar_map ||
        config.lidar_holdout_every != scene.config.lidar_holdout_every)
      io::write_scene_yaml(dir / "scene.yaml", config);
  }
  return report;
}

double peak_rss_mb() {
  std::ifstream status("/proc/self/status");
  std::string line;
  while (std::getline(status, line))
    if (line.rfind("VmHWM:", 0) == 0) return std::stod(line.substr(6)) / 1024.0;  // kB
  return 0;
}

}  // namespace litgs::host
