#include "host/eval/covisibility.h"

#include <Eigen/Core>
#include <algorithm>
#include <cmath>
#include <limits>
#include <stdexcept>
#include <string>
#include <utility>

#include "io/image.h"

namespace litgs::host {
namespace {

struct Pose {
  Eigen::Matrix3d R;  // camera <- world
  Eigen::Vector3d t;
};

Pose pose_of(const kernels::SplatCamera& c) {
  Pose p;
  for (int col = 0; col < 3; ++col) {
    for (int row = 0; row < 3; ++row) p.R(row, col) = c.R_cam_world[col][row];
    p.t[col] = c.t_cam_world[col];
  }
  return p;
}

void check_view(const DepthView& v, const char* what) {
  const size_t pixels = static_cast<size_t>(v.camera.width) * v.camera.height;
  if (pixels == 0 || v.depth_m.size() != pixels)
    throw std::invalid_argument(std::string("covisible_pixels: ") + what + " has " +
                                std::to_string(v.depth_m.size()) + " depth values for a " +
                                std::to_string(v.camera.width) + "x" + std::to_string(v.camera.height) +
                                " camera");
}

// Whether `view` sees the point p_cam (in its camera frame; at infinity along p_cam's direction when
// at_infinity): it projects inside the image and one of the four pixels around it holds the same depth
// (sky where at_infinity).
bool sees(const DepthView& view, const Eigen::Vector3d& p_cam, bool at_infinity,
          const CovisibilityOptions& o) {
  const kernels::SplatCamera& c = view.camera;
  if (!(p_cam.z() > (at_infinity ? 0.0 : c.near_m))) return false;
  const double u = c.fx * p_cam.x() / p_cam.z() + c.cx, v = c.fy * p_cam.y() / p_cam.z() + c.cy;
  if (!(u >= 0 && v >= 0 && u < c.width && v < c.height)) return false;
  // Pixel (i, j) has its centre at (i + 0.5, j + 0.5): the four centres around (u, v).
  const int i0 = static_cast<int>(std::floor(u - 0.5)), j0 = static_cast<int>(std::floor(v - 0.5));
  const double tolerance = std::max(o.min_tolerance_m, o.relative_tolerance * p_cam.z());
  for (int j = std::max(j0, 0); j <= std::min(j0 + 1, static_cast<int>(c.height) - 1); ++j)
    for (int i = std::max(i0, 0); i <= std::min(i0 + 1, static_cast<int>(c.width) - 1); ++i) {
      const float d = view.depth_m[static_cast<size_t>(j) * c.width + i];
      if (at_infinity ? d == 0.0f : (d > 0.0f && std::abs(d - p_cam.z()) <= tolerance)) return true;
    }
  return false;
}

}  // namespace

std::vector<uint8_t> covisible_pixels(const DepthView& target, const std::vector<DepthView>& others,
                                      const CovisibilityOptions& o) {
  check_view(target, "the target view");
  for (const DepthView& v : others) check_view(v, "a training view");
  const kernels::SplatCamera& c = target.camera;
  const Pose target_pose = pose_of(c);
  std::vector<Pose> poses;
  for (const DepthView& v : others) poses.push_back(pose_of(v.camera));

  std::vector<uint8_t> mask(target.depth_m.size(), 0);
  for (uint32_t j = 0; j < c.height; ++j)
    for (uint32_t i = 0; i < c.width; ++i) {
      const size_t p = static_cast<size_t>(j) * c.width + i;
      const double d = target.depth_m[p];
      if (!(d >= 0.0) || !std::isfinite(d)) continue;  // not a depth: not counted
      const bool at_infinity = d == 0.0;
      const Eigen::Vector3d ray((i + 0.5 - c.cx) / c.fx, (j + 0.5 - c.cy) / c.fy, 1.0);
      // A surface point in the world, or a direction for sky.
      const Eigen::Vector3d world =
          at_infinity ? Eigen::Vector3d(target_pose.R.transpose() * ray)
                      : Eigen::Vector3d(target_pose.R.transpose() * (ray * d - target_pose.t));
      for (size_t k = 0; k < others.size() && !mask[p]; ++k) {
        const Eigen::Vector3d p_cam = at_infinity ? Eigen::Vector3d(poses[k].R * world)
                                                  : Eigen::Vector3d(poses[k].R * world + poses[k].t);
        mask[p] = sees(others[k], p_cam, at_infinity, o) ? 1 : 0;
      }
    }
  return mask;
}

std::vector<uint8_t> downscale_mask(const std::vector<uint8_t>& mask, uint32_t width, uint32_t height,
                                    uint32_t out_width, uint32_t out_height) {
  if (mask.size() != static_cast<size_t>(width) * height || out_width == 0 || out_height == 0)
    throw std::invalid_argument("downscale_mask: a mask of " + std::to_string(mask.size()) + " values for " +
                                std::to_string(width) + "x" + std::to_string(height) + " pixels, to " +
                                std::to_string(out_width) + "x" + std::to_string(out_height));
  std::vector<uint32_t> seen(static_cast<size_t>(out_width) * out_height, 0), all(seen.size(), 0);
  for (uint32_t j = 0; j < height; ++j)
    for (uint32_t i = 0; i < width; ++i) {
      const auto oi = std::min<uint32_t>(out_width - 1, static_cast<uint32_t>((i + 0.5) * out_width / width));
      const auto oj =
          std::min<uint32_t>(out_height - 1, static_cast<uint32_t>((j + 0.5) * out_height / height));
      const size_t q = static_cast<size_t>(oj) * out_width + oi;
      ++all[q];
      seen[q] += mask[static_cast<size_t>(j) * width + i];
    }
  std::vector<uint8_t> out(seen.size(), 0);
  for (size_t q = 0; q < out.size(); ++q) out[q] = all[q] > 0 && 2 * seen[q] >= all[q] ? 1 : 0;
  return out;
}

double masked_psnr(std::span<const float> image, std::span<const float> target,
                   const std::vector<uint8_t>& mask) {
  if (image.size() != target.size() || mask.size() != target.size())
    throw std::invalid_argument("masked_psnr: " + std::to_string(image.size()) + " rendered, " +
                                std::to_string(target.size()) + " target and " + std::to_string(mask.size()) +
                                " mask values");
  double sum = 0;
  size_t n = 0;
  for (size_t p = 0; p < target.size(); ++p)
    if (mask[p]) {
      const double e = double{image[p]} - target[p];
      sum += e * e;
      ++n;
    }
  if (n == 0) return std::numeric_limits<double>::quiet_NaN();
  if (sum == 0.0) return std::numeric_limits<double>::infinity();  // as kernels::psnr
  return 10.0 * std::log10(static_cast<double>(n) / sum);
}

HeldoutCovisibility heldout_covisibility(const std::filesystem::path& scene_dir, const io::Scene& scene,
                                         const TrainingData& data, const CovisibilityOptions& o) {
  HeldoutCovisibility out;
  const io::CameraIntrinsics& k = scene.config.camera;
  const bool distorted =
      std::any_of(k.distortion.begin(), k.distortion.end(), [](double c) { return c != 0; });
  if (k.model != io::CameraModel::kPinhole || distorted) {
    out.unavailable = "the camera is not an undistorted pinhole";
    return out;
  }
  if (!scene.gt || scene.gt->poses.empty()) {
    out.unavailable = "the scene has no gt/poses.txt";
    return out;
  }
  if (!std::filesystem::is_directory(scene_dir / "gt/depth")) {
    out.unavailable = "the scene has no gt/depth/";
    return out;
  }
  TrainingDataOptions native = data.options;  // true poses at the frames' own resolution
  native.downscale = 1.0;
  native.true_poses = true;
  std::vector<DepthView> depth(data.views.size());
  for (size_t v = 0; v < data.views.size(); ++v) {
    const std::filesystem::path file = scene_dir / "gt/depth" / data.views[v].name;
    try {
      depth[v].camera = training_camera(scene_dir, scene, data.views[v].t_s, native);
      const io::Image im = io::read_image(file);
      if (im.width != k.width || im.height != k.height || im.channels != 1 || im.bit_depth != 16)
        throw std::invalid_argument(file.string() + ": a " + std::to_string(im.width) + "x" +
                                    std::to_string(im.height) + ", " + std::to_string(im.channels) +
                                    "-channel " + std::to_string(im.bit_depth) +
                                    "-bit image, not the camera's " + std::to_string(k.width) + "x" +
                                    std::to_string(k.height) + " 16-bit depth");
      depth[v].depth_m.resize(im.data.size());
      for (size_t p = 0; p < im.data.size(); ++p) depth[v].depth_m[p] = static_cast<float>(im.data[p] * 1e-3);
    } catch (const std::exception& e) {
      out.unavailable = e.what();  // names the file (or the frame outside gt/poses.txt)
      return out;
    }
  }
  std::vector<DepthView> training;  // moved out: only the held-out views' depth stays in `depth`
  for (size_t v = 0; v < data.views.size(); ++v)
    if (!data.views[v].heldout) training.push_back(std::move(depth[v]));
  out.masks.resize(data.views.size());
  for (size_t v = 0; v < data.views.size(); ++v)
    if (data.views[v].heldout)
      out.masks[v] = downscale_mask(covisible_pixels(depth[v], training, o), static_cast<uint32_t>(k.width),
                                    static_cast<uint32_t>(k.height), data.width, data.height);
  return out;
}

}  // namespace litgs::host
