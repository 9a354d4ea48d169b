// COLMAP sparse models (cameras, images, points3D) in COLMAP's text and binary forms, read and written by a
// small parser of our own (no COLMAP dependency). The layout follows COLMAP's documentation ("Output
// format") and src/colmap/scene/reconstruction_io.cc:
//
//   cameras.txt   CAMERA_ID MODEL WIDTH HEIGHT PARAMS[]
//   images.txt    IMAGE_ID QW QX QY QZ TX TY TZ CAMERA_ID NAME, then one line of POINTS2D[] as (X Y
//   POINT3D_ID) points3D.txt  POINT3D_ID X Y Z R G B ERROR TRACK[] as (IMAGE_ID POINT2D_IDX)
//   *.bin         little-endian: counts uint64, camera/image ids uint32, model id int32, sizes uint64,
//                 numbers float64, names NUL-terminated, colours uint8, point ids uint64 (-1: none)
//
// Conventions of COLMAP kept as they are in these structs (converted only by the importer/exporter):
// (qvec, tvec) maps world points into the camera (cam_from_world); pixel coordinates put the centre of the
// top-left pixel at (0.5, 0.5).
#pragma once

#include <Eigen/Core>
#include <Eigen/Geometry>
#include <array>
#include <cstdint>
#include <filesystem>
#include <map>
#include <string>
#include <vector>

namespace litgs::io {

// COLMAP's camera models by their numeric id (the binary format stores the id, the text format the name).
enum class ColmapCameraModel : int {
  kSimplePinhole = 0,        // f cx cy
  kPinhole = 1,              // fx fy cx cy
  kSimpleRadial = 2,         // f cx cy k
  kRadial = 3,               // f cx cy k1 k2
  kOpenCv = 4,               // fx fy cx cy k1 k2 p1 p2
  kOpenCvFisheye = 5,        // fx fy cx cy k1 k2 k3 k4
  kFullOpenCv = 6,           // fx fy cx cy k1 k2 p1 p2 k3 k4 k5 k6
  kFov = 7,                  // fx fy cx cy omega
  kSimpleRadialFisheye = 8,  // f cx cy k
  kRadialFisheye = 9,        // f cx cy k1 k2
  kThinPrismFisheye = 10,    // fx fy cx cy k1 k2 p1 p2 k3 k4 sx1 sy1
};

// "PINHOLE" etc.; the model's parameter count. Unknown ids/names: false / -1.
std::string colmap_model_name(ColmapCameraModel model);
bool colmap_model_from_name(const std::string& name, ColmapCameraModel& model);
bool colmap_model_from_id(int id, ColmapCameraModel& model);
int colmap_model_num_params(ColmapCameraModel model);

struct ColmapCamera {
  uint32_t id = 0;
  ColmapCameraModel model = ColmapCameraModel::kPinhole;
  uint64_t width = 0, height = 0;  // pixels
  std::vector<double> params;      // as the model lists them; COLMAP's pixel convention
};

struct ColmapPoint2D {
  Eigen::Vector2d xy = Eigen::Vector2d::Zero();  // pixels, COLMAP's convention
  int64_t point3d_id = -1;                       // -1: not triangulated
};

struct ColmapImage {
  uint32_t id = 0;
  // cam_from_world: X_cam = q_cam_world * X_world + t_cam_world. Stored as read (q normalized on read).
  Eigen::Quaterniond q_cam_world = Eigen::Quaterniond::Identity();
  Eigen::Vector3d t_cam_world = Eigen::Vector3d::Zero();
  uint32_t camera_id = 0;
  std::string name;  // relative to the image folder
  std::vector<ColmapPoint2D> points2d;

  // The camera-to-world transform (T_world_cam), 4x4.
  Eigen::Matrix4d T_world_cam() const;
};

struct ColmapTrackElement {
  uint32_t image_id = 0;
  uint32_t point2d_idx = 0;
};

struct ColmapPoint3D {
  uint64_t id = 0;
  Eigen::Vector3d xyz = Eigen::Vector3d::Zero();  // world frame
  std::array<uint8_t, 3> rgb = {0, 0, 0};
  double error_px = -1;  // mean reprojection error; negative: unknown (COLMAP's default -1)
  std::vector<ColmapTrackElement> track;
};

struct ColmapModel {
  std::map<uint32_t, ColmapCamera> cameras;  // by id
  std::vector<ColmapImage> images;           // in file order
  std::vector<ColmapPoint3D> points;         // in file order
};

// Reads a model folder. Binary files (cameras.bin, images.bin, points3D.bin) are preferred when all three
// exist (as COLMAP does), else the three .txt files; points3D is optional (an empty model of points).
// IoError naming the file and the line (text) or byte offset (binary) on: a missing file, a wrong field
// count, an unparsable or non-finite number, an unknown camera model, a parameter count that disagrees with
// the model, a zero quaternion, duplicate ids, truncated binary data or trailing bytes, an image that
// references a missing camera, a track that references a missing image or point2D, a point2D that
// references a missing point3D.
ColmapModel read_colmap_model(const std::filesystem::path& dir);
ColmapModel read_colmap_text(const std::filesystem::path& dir);
ColmapModel read_colmap_binary(const std::filesystem::path& dir);

// Writes cameras/images/points3D as .bin (binary) or .txt into dir (created), each file atomically, with
// numbers that read back exactly. std::invalid_argument on an inconsistent model (parameter counts).
void write_colmap_model(const std::filesystem::path& dir, const ColmapModel& model, bool binary);

}  // namespace litgs::io
