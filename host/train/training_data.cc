#include "host/train/training_data.h"

#include <Eigen/Geometry>
#include <algorithm>
#include <cmath>
#include <stdexcept>
#include <utility>

#include "host/frontend/frozen_frames.h"
#include "host/frontend/intensity.h"
#include "io/lens_distortion.h"
#include "io/scene.h"

namespace litgs::host {
namespace {

// T_world_cam of every frame: the pose at the frame's time in `poses` (matched, else interpolated), moved
// from the IMU to the camera if the scene's poses describe the IMU.
Eigen::Isometry3d pose_at(const io::Scene& scene, const std::vector<io::TumPose>& poses, double t,
                          double tolerance) {
  if (poses.empty()) throw std::invalid_argument("poses.txt has no poses");
  auto it = std::lower_bound(poses.begin(), poses.end(), t,
                             [](const io::TumPose& p, double x) { return p.t_s < x; });
  auto rotation_of = [&](const io::TumPose& p) {
    if (!p.has_rotation)
      throw std::invalid_argument("poses.txt: the pose at t = " + std::to_string(p.t_s) +
                                  " has no rotation (0 0 0 0); training needs full poses");
    return p.q_world_body;
  };
  Eigen::Isometry3d T = Eigen::Isometry3d::Identity();
  const io::TumPose* exact = nullptr;
  if (it != poses.end() && std::abs(it->t_s - t) <= tolerance) exact = &*it;
  if (it != poses.begin() && std::abs(std::prev(it)->t_s - t) <= tolerance) exact = &*std::prev(it);
  if (exact) {
    T.linear() = rotation_of(*exact).toRotationMatrix();
    T.translation() = exact->p_world;
  } else {
    if (it == poses.begin() || it == poses.end())
      throw std::invalid_argument("frame at t = " + std::to_string(t) +
                                  " s lies outside the trajectory of poses.txt");
    const io::TumPose& a = *std::prev(it);
    const io::TumPose& b = *it;
    const double s = (t - a.t_s) / (b.t_s - a.t_s);
    T.linear() = rotation_of(a).slerp(s, rotation_of(b)).toRotationMatrix();
    T.translation() = (1 - s) * a.p_world + s * b.p_world;
  }
  if (scene.config.poses_frame == io::PoseFrame::kImu) {
    const Eigen::Matrix4d T_imu_cam = scene.config.T_imu_lidar * scene.config.T_cam_lidar.inverse();
    T = T * Eigen::Isometry3d(T_imu_cam);
  }
  return T;
}

// Bilinear sample at OpenCV pixel coordinates (pixel centres at integers); -1 outside the image.
double sample(const std::vector<float>& img, int w, int h, double u, double v) {
  if (u < -0.5 || v < -0.5 || u > w - 0.5 || v > h - 0.5) return -1.0;
  const double uc = std::clamp(u, 0.0, w - 1.0), vc = std::clamp(v, 0.0, h - 1.0);
  const int x0 = std::min(static_cast<int>(uc), w - 2 < 0 ? 0 : w - 2),
            y0 = std::min(static_cast<int>(vc), h - 2 < 0 ? 0 : h - 2);
  const int x1 = std::min(x0 + 1, w - 1), y1 = std::min(y0 + 1, h - 1);
  const double fx = uc - x0, fy = vc - y0;
  auto at = [&](int x, int y) { return static_cast<double>(img[static_cast<size_t>(y) * w + x]); };
  return (1 - fy) * ((1 - fx) * at(x0, y0) + fx * at(x1, y0)) +
         fy * ((1 - fx) * at(x0, y1) + fx * at(x1, y1));
}

// The training resolution and its pinhole intrinsics (pixel centres at +0.5, the rasterizer's convention).
struct Pinhole {
  uint32_t W, H;
  double sx, sy;  // original pixels per training pixel
  double fx, fy, cx, cy;
};

Pinhole training_pinhole(const io::CameraIntrinsics& k, double downscale) {
  Pinhole p;
  p.W = static_cast<uint32_t>(std::max(1.0, std::round(k.width / downscale)));
  p.H = static_cast<uint32_t>(std::max(1.0, std::round(k.height / downscale)));
  p.sx = static_cast<double>(k.width) / p.W;
  p.sy = static_cast<double>(k.height) / p.H;
  p.fx = k.fx / p.sx;
  p.fy = k.fy / p.sy;
  p.cx = (k.cx + 0.5) / p.sx;
  p.cy = (k.cy + 0.5) / p.sy;
  return p;
}

kernels::SplatCamera make_camera(const Eigen::Isometry3d& T_world_cam, const Pinhole& p) {
  kernels::SplatCamera camera;
  const Eigen::Matrix3d R = T_world_cam.linear().transpose();
  const Eigen::Vector3d t = -R * T_world_cam.translation();
  for (int c = 0; c < 3; ++c) {
    for (int r = 0; r < 3; ++r) camera.R_cam_world[c][r] = R(r, c);
    camera.t_cam_world[c] = t[c];
  }
  camera.fx = p.fx;
  camera.fy = p.fy;
  camera.cx = p.cx;
  camera.cy = p.cy;
  camera.width = p.W;
  camera.height = p.H;
  return camera;
}

const std::vector<io::TumPose>& training_poses(const std::filesystem::path& dir, const io::Scene& scene,
                                               bool true_poses) {
  if (true_poses && (!scene.gt || scene.gt->poses.empty()))
    throw std::invalid_argument(dir.string() +
                                ": training on true poses needs gt/poses.txt, which the scene lacks");
  return true_poses ? scene.gt->poses : scene.poses;
}

}  // namespace

kernels::SplatCamera training_camera(const std::filesystem::path& scene_dir, const io::Scene& scene,
                                     double t_s, const TrainingDataOptions& o) {
  o.check();
  const std::vector<io::TumPose>& poses = training_poses(scene_dir, scene, o.true_poses);
  return make_camera(pose_at(scene, poses, t_s, o.pose_match_tolerance_s),
                     training_pinhole(scene.config.camera, o.downscale));
}

void TrainingDataOptions::check() const {
  if (!(downscale >= 1.0) || !std::isfinite(downscale))
    throw std::invalid_argument("TrainingDataOptions.downscale = " + std::to_string(downscale) +
                                " must be >= 1");
  if (!(low_percentile >= 0 && low_percentile < high_percentile && high_percentile <= 100))
    throw std::invalid_argument("TrainingDataOptions: percentiles must satisfy 0 <= low < high <= 100");
  if (!(frozen_threshold >= 0))
    throw std::invalid_argument("TrainingDataOptions.frozen_threshold must be >= 0");
}

frontend::Stretch percentile_window(const io::SceneConfig& config, const frontend::Histogram& all_frames,
                                    const TrainingDataOptions& o) {
  if (config.intensity_window) return {config.intensity_window->first, config.intensity_window->second};
  return frontend::percentile_stretch(all_frames, o.low_percentile, o.high_percentile);
}

TrainingData load_training_data(const std::filesystem::path& dir, const TrainingDataOptions& o) {
  o.check();
  io::SceneReadOptions read;
  read.load_map = false;
  const io::Scene scene = io::read_scene(dir, read);
  const io::CameraIntrinsics& k = scene.config.camera;
  if (scene.frames.empty()) throw std::invalid_argument(dir.string() + ": the scene has no thermal frames");
  const std::vector<io::TumPose>& poses = training_poses(dir, scene, o.true_poses);

  // Raw frames, and the intensity mapping shared by all of them.
  std::vector<std::vector<float>> raw(scene.frames.size());
  frontend::Histogram histogram = frontend::empty_histogram();
  for (size_t i = 0; i < scene.frames.size(); ++i) {
    const io::Image img = io::load_frame(dir, scene, i);
    raw[i].resize(static_cast<size_t>(img.width) * img.height);
    for (size_t p = 0; p < raw[i].size(); ++p) raw[i][p] = img.data[p * img.channels];
    frontend::add_to_histogram(histogram, img.data, static_cast<size_t>(img.channels));
  }
  TrainingData out;
  out.options = o;
  const bool percentile = o.mapping == IntensityMapping::kPercentile ||
                          (o.mapping == IntensityMapping::kAuto && k.bit_depth == 16);
  frontend::Stretch stretch{0, k.bit_depth == 16 ? 65535.0 : 255.0};
  if (percentile) stretch = percentile_window(scene.config, histogram, o);
  out.stretch_low = stretch.low;
  out.stretch_high = stretch.high;
  for (auto& frame : raw)
    for (float& v : frame) v = stretch.unit(v);

  // Training resolution and pinhole camera (pixel centres at +0.5, the rasterizer's convention).
  const Pinhole pinhole = training_pinhole(k, o.downscale);
  const uint32_t W = pinhole.W, H = pinhole.H;
  const double sx = pinhole.sx, sy = pinhole.sy;
  const double fx = pinhole.fx, fy = pinhole.fy, cx = pinhole.cx, cy = pinhole.cy;
  out.width = W;
  out.height = H;
  out.world_offset_m = scene.config.world_offset_m;
  // Supersample each training pixel so that downscaling averages instead of aliasing.
  const int sub = std::max(1, static_cast<int>(std::ceil(std::max(sx, sy))));

  std::vector<Eigen::Vector3d> centres;
  frontend::FrozenFrameDetector frozen(o.frozen_threshold);
  bool skipped_before = false;
  for (size_t i = 0; i < scene.frames.size(); ++i) {
    if (frozen.is_frozen(raw[i])) {
      ++out.frozen_skipped;
      skipped_before = true;
      continue;
    }
    TrainingView view;
    view.after_frozen = std::exchange(skipped_before, false);
    view.name = scene.frames[i].image.filename().string();
    view.t_s = scene.frames[i].t_s;
    view.heldout = o.holdout_every > 0 && i % o.holdout_every == 0;
    const Eigen::Isometry3d T_world_cam = pose_at(scene, poses, view.t_s, o.pose_match_tolerance_s);
    view.camera = make_camera(T_world_cam, pinhole);
    centres.push_back(T_world_cam.translation());

    view.image.assign(static_cast<size_t>(W) * H, 0.0f);
    for (uint32_t y = 0; y < H; ++y)
      for (uint32_t x = 0; x < W; ++x) {
        double sum = 0;
        int count = 0;
        for (int sy_i = 0; sy_i < sub; ++sy_i)
          for (int sx_i = 0; sx_i < sub; ++sx_i) {
            const double px = x + (sx_i + 0.5) / sub, py = y + (sy_i + 0.5) / sub;  // training pixel coords
            const Eigen::Vector2d d = io::distort_normalized(k, {(px - cx) / fx, (py - cy) / fy});
            const double v = sample(raw[i], k.width, k.height, k.fx * d.x() + k.cx, k.fy * d.y() + k.cy);
            if (v >= 0) {
              sum += v;
              ++count;
            }
          }
        view.image[static_cast<size_t>(y) * W + x] = count ? static_cast<float>(sum / count) : 0.0f;
      }
    out.views.push_back(std::move(view));
  }
  Eigen::Vector3d mean = Eigen::Vector3d::Zero();
  for (const auto& c : centres) mean += c;
  mean /= static_cast<double>(centres.size());
  double radius = 0;
  for (const auto& c : centres) radius = std::max(radius, (c - mean).norm());
  out.scene_extent_m = std::max(1.1 * radius, 1e-3);
  return out;
}

std::vector<kernels::SplatCamera> training_cameras(const TrainingData& data) {
  std::vector<kernels::SplatCamera> cameras;
  for (const TrainingView& v : data.views)
    if (!v.heldout) cameras.push_back(v.camera);
  return cameras;
}

}  // namespace litgs::host
