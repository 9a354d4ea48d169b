// `litgs-engine import colmap`: a COLMAP sparse model (text or binary) plus its image folder into a scene
// directory (docs/scene-format.md, "Importing from COLMAP"). Also the camera conversions that the COLMAP
// exporter shares.
#pragma once

#include <Eigen/Core>
#include <filesystem>
#include <optional>
#include <string>
#include <vector>

#include "io/colmap.h"
#include "io/scene_types.h"

namespace litgs::io {

struct ColmapImportOptions {
  std::filesystem::path model;   // folder with cameras/images/points3D as .bin or .txt
  std::filesystem::path images;  // folder the images' NAMEs are relative to
  std::filesystem::path out;     // scene directory to write (created; must not hold other frames)
  // Recentring offset subtracted from world positions; default: the mean camera centre rounded to whole
  // metres (as the Metashape importer does; exactly representable).
  std::optional<Eigen::Vector3d> world_offset_m;
  std::string image_extension = ".png";  // of the written frames: ".png" or ".tiff"
  bool points_as_anchors = true;         // write points3D as anchors.txt (see import_colmap)
  // Floor of a point's reprojection error when its covariance is derived from it (COLMAP's errors can be
  // 0 for two-view points, or unknown, -1). Pixels, > 0.
  double anchor_min_error_px = 0.5;

  // Throws std::invalid_argument naming the bad field.
  void check() const;
};

struct ColmapImportReport {
  size_t frames = 0;   // images written
  size_t anchors = 0;  // points3D written as anchors
  Eigen::Vector3d world_offset_m = Eigen::Vector3d::Zero();
  std::vector<std::string> notes;  // conversions a user should know about
};

// The scene camera of a COLMAP camera. COLMAP puts the centre of the top-left pixel at (0.5, 0.5), the
// scene at (0, 0): cx, cy move by -0.5. SIMPLE_PINHOLE, PINHOLE -> pinhole without distortion;
// SIMPLE_RADIAL (k), RADIAL (k1 k2) -> pinhole [k1 k2 0 0]; OPENCV -> pinhole [k1 k2 p1 p2];
// FULL_OPENCV with k4 = k5 = k6 = 0 -> pinhole [k1 k2 p1 p2 k3]; OPENCV_FISHEYE -> equidistant
// [k1 k2 k3 k4]. All-zero distortion becomes none. IoError naming `file` and the camera for any other
// model (FOV, the radial fisheyes, thin prism, FULL_OPENCV with a rational part). bit_depth is left as is.
CameraIntrinsics scene_camera_from_colmap(const ColmapCamera& camera, const std::filesystem::path& file);

// The inverse: pinhole without distortion -> PINHOLE, with 4 -> OPENCV, with 5 -> FULL_OPENCV (k4..k6 = 0);
// equidistant -> OPENCV_FISHEYE.
ColmapCamera colmap_camera_from_scene(const CameraIntrinsics& camera, uint32_t id);

// Converts and writes the scene:
// - poses: T_world_cam = inverse of COLMAP's cam_from_world (qvec, tvec), recentred by world_offset_m,
//   written as TUM camera poses;
// - timestamps: the stem of every image NAME if all of them are numbers (seconds; what `export colmap`
//   writes), else each image's id (noted);
// - intrinsics: scene_camera_from_colmap; the registered images must share one camera (or cameras with
//   identical parameters);
// - images: read (PNG/TIFF, 8/16 bit) and written with their values unchanged; 3- or 4-channel images
//   whose colour channels are equal keep one channel, other colour images are an IoError (thermal frames
//   are single-channel);
// - points3D -> anchors.txt (points_as_anchors): position, and an isotropic covariance sigma^2 I with
//   sigma = max(ERROR, anchor_min_error_px) * mean depth over the point's track / mean focal length (the
//   reprojection error as a metric uncertainty); a point without a usable track takes its distance to the
//   nearest camera centre as the depth. Colours and tracks are not kept.
// - no LiDAR map (lidar_map: false), identity extrinsics as placeholders, no IMU.
// IoError or std::invalid_argument on unreadable input (read_colmap_model), an unsupported camera, an
// image that is missing or disagrees with its camera, duplicate timestamps.
ColmapImportReport import_colmap(const ColmapImportOptions& options);

}  // namespace litgs::io
