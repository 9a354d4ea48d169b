#include "io/export_scene.h"

#include <Eigen/Geometry>
#include <algorithm>
#include <stdexcept>

#include "io/atomic_file.h"
#include "io/colmap.h"
#include "io/error.h"
#include "io/import_colmap.h"
#include "io/sfm_files.h"
#include "io/tum.h"

namespace litgs::io {
namespace fs = std::filesystem;
namespace {

Eigen::Matrix4d rigid_inverse(const Eigen::Matrix4d& T) {
  Eigen::Matrix4d inv = Eigen::Matrix4d::Identity();
  inv.topLeftCorner<3, 3>() = T.topLeftCorner<3, 3>().transpose();
  inv.topRightCorner<3, 1>() = -T.topLeftCorner<3, 3>().transpose() * T.topRightCorner<3, 1>();
  return inv;
}

// Copies a file byte for byte through a temporary name.
void copy_atomic(const fs::path& from, const fs::path& to) {
  AtomicFile file(to);
  std::error_code ec;
  fs::copy_file(from, file.temp_path(), fs::copy_options::overwrite_existing, ec);
  if (ec) fail(from, 0, "cannot copy to " + to.string() + ": " + ec.message());
  file.commit();
}

// points3D with their tracks from the front end's sfm/, and every keypoint of each exported image as a
// point2D (COLMAP's pixel convention: + 0.5); keeps every k-th point to stay within max_points.
void add_sfm_points(const SfmData& sfm, const Scene& scene, const fs::path& sfm_dir,
                    const std::vector<int64_t>& image_of_frame, const Eigen::Vector3d& offset,
                    size_t max_points, ColmapModel& model, ColmapExportReport& report) {
  if (sfm.images.size() != scene.frames.size())
    fail(sfm_dir / "images.txt", 0,
         "lists " + std::to_string(sfm.images.size()) + " images, the scene has " +
             std::to_string(scene.frames.size()) + " frames: run `litgs-engine match` again");
  for (size_t i = 0; i < sfm.images.size(); ++i) {
    if (sfm.images[i].frame != scene.frames[i].image.generic_string())
      fail(sfm_dir / "images.txt", static_cast<int64_t>(i) + 2,
           "image " + std::to_string(i) + " is " + sfm.images[i].frame + ", the scene's frame is " +
               scene.frames[i].image.generic_string() + ": run `litgs-engine match` again");
    if (image_of_frame[i] < 0) continue;
    for (const SfmKeypoint& k : sfm.images[i].keypoints)
      model.images[static_cast<size_t>(image_of_frame[i])].points2d.push_back(
          {Eigen::Vector2d(k.x + 0.5, k.y + 0.5), -1});
  }
  const size_t step = std::max<size_t>(1, (sfm.points.size() + max_points - 1) / max_points);
  if (step > 1) report.notes.push_back("kept one point in " + std::to_string(step));
  for (size_t i = 0; i < sfm.points.size(); i += step) {
    ColmapPoint3D p;
    p.id = model.points.size() + 1;
    p.xyz = sfm.points[i].xyz + offset;
    p.rgb = {128, 128, 128};
    p.error_px = sfm.points[i].error_px;
    for (const SfmObservation& obs : sfm.points[i].observations) {
      if (image_of_frame[obs.image] < 0) continue;
      ColmapImage& im = model.images[static_cast<size_t>(image_of_frame[obs.image])];
      im.points2d[obs.keypoint].point3d_id = static_cast<int64_t>(p.id);
      p.track.push_back({im.id, obs.keypoint});
    }
    if (p.track.size() >= 2) {
      model.points.push_back(std::move(p));
    } else {
      for (const auto& t : p.track) model.images[t.image_id - 1].points2d[t.point2d_idx].point3d_id = -1;
    }
  }
  report.notes.push_back("points3D and their 2D observations from sfm/ (litgs-engine match)");
}

}  // namespace

std::vector<std::optional<Eigen::Matrix4d>> camera_poses_at_frames(const Scene& scene) {
  const SceneConfig& c = scene.config;
  const bool imu = c.poses_frame == PoseFrame::kImu;
  const Eigen::Matrix4d T_imu_cam = c.T_imu_lidar * rigid_inverse(c.T_cam_lidar);
  std::vector<std::optional<Eigen::Matrix4d>> out;
  for (const auto& f : scene.frames) {
    std::optional<Eigen::Matrix4d> T =
        tum_pose_at(scene.poses, imu ? f.t_s + c.time_offset_cam_lidar_s : f.t_s);
    if (T && imu) T = *T * T_imu_cam;
    out.push_back(T);
  }
  return out;
}

void ColmapExportOptions::check() const {
  if (scene.empty()) throw std::invalid_argument("scene: required");
  if (out.empty()) throw std::invalid_argument("out: required");
  if (!fs::is_directory(scene)) throw std::invalid_argument("scene: not a directory: " + scene.string());
}

ColmapExportReport export_colmap(const ColmapExportOptions& o) {
  o.check();
  const Scene scene = read_scene(o.scene, {.check_images = true, .load_map = o.max_points > 0});
  const Eigen::Vector3d offset = o.recentred ? Eigen::Vector3d::Zero() : scene.config.world_offset_m;
  ColmapExportReport report;

  ColmapModel model;
  model.cameras[1] = colmap_camera_from_scene(scene.config.camera, 1);
  const auto poses = camera_poses_at_frames(scene);
  const fs::path images_dir = o.out / "images";
  fs::create_directories(images_dir);
  std::vector<int64_t> image_of_frame(scene.frames.size(), -1);  // index into model.images
  for (size_t i = 0; i < scene.frames.size(); ++i) {
    if (!poses[i]) {
      ++report.skipped_without_pose;
      continue;
    }
    const Eigen::Matrix4d& T_world_cam = *poses[i];
    ColmapImage im;
    im.id = static_cast<uint32_t>(model.images.size() + 1);
    const Eigen::Matrix3d R_cam_world = T_world_cam.topLeftCorner<3, 3>().transpose();
    im.q_cam_world = Eigen::Quaterniond(R_cam_world).normalized();
    im.t_cam_world = -R_cam_world * (T_world_cam.topRightCorner<3, 1>() + offset);
    im.camera_id = 1;
    im.name = scene.frames[i].image.filename().string();
    copy_atomic(o.scene / scene.frames[i].image, images_dir / im.name);
    image_of_frame[i] = static_cast<int64_t>(model.images.size());
    model.images.push_back(std::move(im));
  }
  if (report.skipped_without_pose)
    report.notes.push_back(std::to_string(report.skipped_without_pose) +
                           " frames outside the trajectory (or next to unknown rotations) left out");

  const fs::path sfm_dir = o.scene / "sfm";
  if (o.max_points > 0 && has_sfm(sfm_dir)) {
    add_sfm_points(read_sfm(sfm_dir), scene, sfm_dir, image_of_frame, offset, o.max_points, model, report);
  } else if (o.max_points > 0) {
    std::vector<Eigen::Vector3d> points;
    if (!scene.anchors.empty()) {
      for (const auto& a : scene.anchors) points.push_back(a.p_world);
      report.notes.push_back("points3D from anchors.txt");
    } else if (scene.map) {
      points = scene.map->positions;
      report.notes.push_back("points3D from the LiDAR map (" + std::to_string(points.size()) + " points)");
    } else {
      report.notes.push_back(
          "no points3D: the scene has no sfm/ (litgs-engine match), anchors.txt or LiDAR map (litgs-engine "
          "map builds one from the scans)");
    }
    const size_t step = (points.size() + o.max_points - 1) / o.max_points;
    if (step > 1) report.notes.push_back("kept one point in " + std::to_string(step));
    for (size_t i = 0; i < points.size(); i += std::max<size_t>(step, 1)) {
      ColmapPoint3D p;
      p.id = model.points.size() + 1;
      p.xyz = points[i] + offset;
      p.rgb = {128, 128, 128};
      p.error_px = -1;
      model.points.push_back(p);
    }
  }
  write_colmap_model(o.out / "sparse/0", model, o.binary);
  report.images = model.images.size();
  report.points = model.points.size();
  return report;
}

std::vector<TumPose> imu_trajectory(const SceneConfig& c, const std::vector<TumPose>& poses,
                                    const fs::path& file) {
  if (c.poses_frame == PoseFrame::kImu) return poses;
  const Eigen::Matrix4d T_cam_imu = c.T_cam_lidar * rigid_inverse(c.T_imu_lidar);
  std::vector<TumPose> out;
  out.reserve(poses.size());
  for (size_t i = 0; i < poses.size(); ++i) {
    if (!poses[i].has_rotation)
      fail(file, static_cast<int64_t>(i) + 1,
           "a camera pose of unknown rotation cannot be moved to the IMU (the lever arm needs the rotation)");
    Eigen::Matrix4d T = Eigen::Matrix4d::Identity();
    T.topLeftCorner<3, 3>() = poses[i].q_world_body.toRotationMatrix();
    T.topRightCorner<3, 1>() = poses[i].p_world;
    T = T * T_cam_imu;
    TumPose p;
    p.t_s = poses[i].t_s + c.time_offset_cam_lidar_s;
    p.p_world = T.topRightCorner<3, 1>();
    p.q_world_body = Eigen::Quaterniond(Eigen::Matrix3d(T.topLeftCorner<3, 3>())).normalized();
    out.push_back(p);
  }
  return out;
}

void TumExportOptions::check() const {
  if (scene.empty()) throw std::invalid_argument("scene: required");
  if (out.empty()) throw std::invalid_argument("out: required");
  if (!fs::is_directory(scene)) throw std::invalid_argument("scene: not a directory: " + scene.string());
  if (camera && ground_truth) throw std::invalid_argument("camera: not with ground_truth");
  if (camera && imu) throw std::invalid_argument("imu: not with camera");
}

size_t export_tum(const TumExportOptions& o) {
  o.check();
  const Scene scene = read_scene(o.scene, {.check_images = false, .load_map = false});
  const Eigen::Vector3d offset = o.recentred ? Eigen::Vector3d::Zero() : scene.config.world_offset_m;
  std::vector<TumPose> poses;
  if (o.camera) {
    const auto T = camera_poses_at_frames(scene);
    for (size_t i = 0; i < T.size(); ++i) {
      if (!T[i]) continue;
      TumPose p;
      p.t_s = scene.frames[i].t_s;
      p.p_world = T[i]->topRightCorner<3, 1>();
      p.q_world_body = Eigen::Quaterniond(Eigen::Matrix3d(T[i]->topLeftCorner<3, 3>())).normalized();
      poses.push_back(p);
    }
  } else if (o.ground_truth) {
    if (!scene.gt || scene.gt->poses.empty())
      fail(o.scene / "gt/poses.txt", 0, "missing (no ground-truth poses)");
    poses = scene.gt->poses;
  } else {
    poses = scene.poses;
  }
  if (o.imu)
    poses = imu_trajectory(scene.config, poses, o.scene / (o.ground_truth ? "gt/poses.txt" : "poses.txt"));
  for (auto& p : poses) p.p_world += offset;
  write_tum(o.out, poses);
  return poses.size();
}

}  // namespace litgs::io
