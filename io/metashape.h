// Agisoft Metashape camera XML ("File > Export > Cameras", document version 1.x): sensors with their
// calibration, cameras with their camera-to-chunk pose, the chunk transform to the metric reference frame,
// and markers (control points) with their image observations.
//
// Frames. Metashape cameras look down +z with x right and y down (as OpenCV). A camera's <transform> maps
// camera points into the chunk frame (T_chunk_cam, rigid); the chunk <transform> maps chunk points into the
// reference ("world") frame with a similarity: X_world = scale * R * X_chunk + t.
//
// Pixels. Metashape measures image coordinates from the top-left corner of the top-left pixel (its centre is
// at 0.5, 0.5) and stores the principal point as an offset (cx, cy) from the image centre: the projection is
//   u = width/2 + cx + f*x' (+ b1*x' + b2*y'),  v = height/2 + cy + f*y'
// with x', y' the distorted normalized coordinates. Its tangential terms are swapped against OpenCV:
//   x' = x*radial + p1*(r^2 + 2x^2) + 2*p2*x*y  (OpenCV: 2*p1*x*y + p2*(r^2 + 2x^2)).
#pragma once

#include <Eigen/Core>
#include <filesystem>
#include <optional>
#include <string>
#include <vector>

namespace litgs::io {

// A Metashape "frame" (pinhole + Brown) calibration, in Metashape's conventions (see above). Fields absent
// from the file stay 0.
struct MetashapeCalibration {
  int width = 0, height = 0;
  double f = 0;           // focal length, pixels
  double cx = 0, cy = 0;  // principal point offset from the image centre, pixels
  double k1 = 0, k2 = 0, k3 = 0, k4 = 0;
  double p1 = 0, p2 = 0;  // Metashape order (swapped against OpenCV)
  double b1 = 0, b2 = 0;  // affinity and skew
  // Projects a camera-frame point to Metashape pixel coordinates (corner origin). z must be > 0.
  Eigen::Vector2d project(const Eigen::Vector3d& p_cam) const;
};

struct MetashapeSensor {
  int id = -1;
  std::string label;
  int width = 0, height = 0;
  std::optional<MetashapeCalibration> calibration;  // the <calibration> element, if any
};

struct MetashapeCamera {
  int id = -1;
  int sensor_id = -1;
  std::string label;                           // usually the image file name without extension
  std::optional<Eigen::Matrix4d> T_chunk_cam;  // absent for cameras Metashape did not align
};

struct MetashapeObservation {
  int camera_id = -1;
  Eigen::Vector2d uv = Eigen::Vector2d::Zero();  // Metashape pixel coordinates (corner origin)
};

struct MetashapeMarker {
  int id = -1;
  std::string label;
  std::optional<Eigen::Vector3d> reference;  // surveyed world coordinates, if given
  bool reference_enabled = false;
  std::vector<MetashapeObservation> observations;  // from <frames><frame><markers>
};

// X_world = scale * R * X_chunk + t.
struct MetashapeChunkTransform {
  Eigen::Matrix3d R = Eigen::Matrix3d::Identity();
  Eigen::Vector3d t = Eigen::Vector3d::Zero();
  double scale = 1;
};

struct MetashapeDocument {
  std::vector<MetashapeSensor> sensors;
  std::vector<MetashapeCamera> cameras;
  std::vector<MetashapeMarker> markers;
  MetashapeChunkTransform chunk;  // identity when the chunk has no <transform>

  const MetashapeSensor* sensor(int id) const;
  const MetashapeCamera* camera(int id) const;
  // The camera's rigid pose in the world frame (T_world_cam: camera points to world), the chunk's scale
  // applied to the translation. Throws std::invalid_argument if the camera has no transform.
  Eigen::Matrix4d T_world_cam(const MetashapeCamera& camera) const;
};

// Reads the first chunk of a camera XML. IoError (file, line, problem) on a missing file, malformed XML, a
// transform that is not 16 (camera) or 9+3+1 (chunk) finite numbers, a camera rotation that is not
// orthonormal, a camera naming an unknown sensor, a non-positive scale or focal length.
MetashapeDocument read_metashape_xml(const std::filesystem::path& path);

// Reads a stand-alone calibration file (root <calibration>, e.g. DUNR-GeoCamCal-TIR.xml).
MetashapeCalibration read_metashape_calibration(const std::filesystem::path& path);

}  // namespace litgs::io
