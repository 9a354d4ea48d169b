// Small scene directories for the front end's tests: a pinhole camera looking at a textured plane z = 5 m
// (world), rendered exactly by ray casting, with the poses as priors. 8-bit frames unless asked otherwise.
#pragma once

#include <Eigen/Geometry>
#include <cmath>
#include <cstdint>
#include <filesystem>
#include <functional>
#include <vector>

#include "io/scene.h"

namespace litgs::testing {

constexpr double kPlaneZ = 5.0;

// Multi-octave value noise in [0, 1]: blobs from 0.4 m down to 5 cm, so corners exist at every scale.
inline double plane_texture(double x, double y) {
  auto hash = [](int64_t i, int64_t j, int octave) {
    uint64_t h = static_cast<uint64_t>(i) * 0x9E3779B97F4A7C15ull ^
                 static_cast<uint64_t>(j) * 0xC2B2AE3D27D4EB4Full ^
                 static_cast<uint64_t>(octave) * 0x165667B19E3779F9ull;
    h ^= h >> 31;
    h *= 0xBF58476D1CE4E5B9ull;
    h ^= h >> 29;
    return static_cast<double>(h >> 11) / 9007199254740992.0;
  };
  double value = 0, weight = 0, cell = 0.4, w = 1;
  for (int octave = 0; octave < 4; ++octave, cell *= 0.5, w *= 0.7) {
    const double u = x / cell, v = y / cell;
    const double u0 = std::floor(u), v0 = std::floor(v);
    const auto i = static_cast<int64_t>(u0), j = static_cast<int64_t>(v0);
    double fu = u - u0, fv = v - v0;
    fu = fu * fu * (3 - 2 * fu);
    fv = fv * fv * (3 - 2 * fv);
    const double a = hash(i, j, octave), b = hash(i + 1, j, octave), c = hash(i, j + 1, octave),
                 d = hash(i + 1, j + 1, octave);
    value += w * ((1 - fv) * ((1 - fu) * a + fu * b) + fv * ((1 - fu) * c + fu * d));
    weight += w;
  }
  return value / weight;
}

struct PlaneCamera {
  int width = 320, height = 240;
  double fx = 300, fy = 300, cx = 159.5, cy = 119.5;
};

// T_world_cam looking along +z from `centre`, turned by `yaw_deg` about the camera's y axis.
inline Eigen::Isometry3d plane_view(const Eigen::Vector3d& centre, double yaw_deg = 0) {
  Eigen::Isometry3d T = Eigen::Isometry3d::Identity();
  T.linear() = Eigen::AngleAxisd(yaw_deg * M_PI / 180.0, Eigen::Vector3d::UnitY()).toRotationMatrix();
  T.translation() = centre;
  return T;
}

// The plane seen from T_world_cam (2x2 supersampled); pixels beyond the horizon are 0.
inline io::Image render_plane(const PlaneCamera& k, const Eigen::Isometry3d& T_world_cam, int bit_depth = 8) {
  io::Image img;
  img.width = k.width;
  img.height = k.height;
  img.bit_depth = bit_depth;
  img.data.resize(static_cast<size_t>(k.width) * k.height);
  const double top = bit_depth == 16 ? 60000.0 : 255.0;
  for (int y = 0; y < k.height; ++y)
    for (int x = 0; x < k.width; ++x) {
      double sum = 0;
      for (int s = 0; s < 4; ++s) {
        const double u = x - 0.25 + 0.5 * (s % 2), v = y - 0.25 + 0.5 * (s / 2);
        const Eigen::Vector3d ray =
            T_world_cam.linear() * Eigen::Vector3d((u - k.cx) / k.fx, (v - k.cy) / k.fy, 1);
        const double t = (kPlaneZ - T_world_cam.translation().z()) / ray.z();
        if (t > 0) {
          const Eigen::Vector3d p = T_world_cam.translation() + t * ray;
          sum += plane_texture(p.x(), p.y());
        }
      }
      img.data[static_cast<size_t>(y) * k.width + x] = static_cast<uint16_t>(std::lround(top * sum / 4));
    }
  return img;
}

// Writes a scene (frames at t = 1, 2, ...; camera poses as priors; no LiDAR map) with the given images.
inline void write_plane_scene(const std::filesystem::path& dir, const PlaneCamera& k,
                              const std::vector<Eigen::Isometry3d>& poses,
                              const std::vector<io::Image>& images) {
  io::Scene scene;
  scene.config.camera.width = k.width;
  scene.config.camera.height = k.height;
  scene.config.camera.fx = k.fx;
  scene.config.camera.fy = k.fy;
  scene.config.camera.cx = k.cx;
  scene.config.camera.cy = k.cy;
  scene.config.camera.bit_depth = images.empty() ? 8 : images[0].bit_depth;
  scene.config.has_lidar_map = false;
  scene.config.poses_frame = io::PoseFrame::kCamera;
  for (size_t i = 0; i < poses.size(); ++i) {
    const double t = static_cast<double>(i + 1);
    scene.frames.push_back({t, io::frame_file_name(t)});
    io::TumPose p;
    p.t_s = t;
    p.p_world = poses[i].translation();
    p.q_world_body = Eigen::Quaterniond(poses[i].linear());
    scene.poses.push_back(p);
  }
  io::write_scene(dir, scene, [&](size_t i) { return images.at(i); });
}

// Renders each pose and writes the scene.
inline void write_rendered_plane_scene(const std::filesystem::path& dir, const PlaneCamera& k,
                                       const std::vector<Eigen::Isometry3d>& poses, int bit_depth = 8) {
  std::vector<io::Image> images;
  for (const auto& T : poses) images.push_back(render_plane(k, T, bit_depth));
  write_plane_scene(dir, k, poses, images);
}

}  // namespace litgs::testing
