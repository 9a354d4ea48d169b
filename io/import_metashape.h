// `litgs-engine import metashape`: an Agisoft Metashape camera XML plus its image folder into a scene
// directory (docs/scene-format.md, "Importing from Metashape").
#pragma once

#include <Eigen/Core>
#include <filesystem>
#include <optional>
#include <string>
#include <vector>

namespace litgs::io {

struct MetashapeImportOptions {
  std::filesystem::path xml;     // camera XML (File > Export > Cameras)
  std::filesystem::path images;  // folder with <camera label>.tiff|.tif|.png
  std::filesystem::path out;     // scene directory to write (created; must not hold other frames)
  // Optional stand-alone calibration XML (root <calibration>) that replaces the sensor's own.
  std::filesystem::path calibration;
  // Recentring offset subtracted from world positions; default: the mean camera centre rounded to whole
  // metres (exactly representable, so original = scene + offset holds to the bit).
  std::optional<Eigen::Vector3d> world_offset_m;
  std::string image_extension = ".png";  // of the written frames: ".png" or ".tiff"

  // Throws std::invalid_argument naming the bad field.
  void check() const;
};

struct MetashapeImportReport {
  size_t frames = 0;             // cameras written
  size_t skipped_unaligned = 0;  // cameras without a pose (not written)
  Eigen::Vector3d world_offset_m = Eigen::Vector3d::Zero();
  std::vector<std::string> notes;  // conversions a user should know about
};

// Converts and writes the scene. Frame timestamps come from labels "HH-MM-SS-mmm..." (seconds of the day,
// e.g. 22-18-41-880-radiometric -> 80321.88); labels that do not follow that pattern get their camera
// index in seconds (noted). IoError or std::invalid_argument on unreadable input, a camera whose image is
// missing or disagrees with the sensor, cameras of several sensors, a sensor without calibration, or a
// calibration the pinhole scene camera cannot hold (k4, skew b2).
MetashapeImportReport import_metashape(const MetashapeImportOptions& options);

}  // namespace litgs::io
