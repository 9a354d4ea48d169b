// The front end's results in a scene directory, `sfm/` (docs/frontend.md, "The sfm/ folder"): keypoints,
// matches per pair with inlier flags, tracks, triangulated points with their observations, and
// frontend.json (the run's summary, written by the front end; not read here).
#pragma once

#include <Eigen/Core>
#include <array>
#include <cstdint>
#include <filesystem>
#include <string>
#include <vector>

namespace litgs::io {

// Pixels in the frame as stored (distorted), OpenCV convention: centre of the top-left pixel at (0, 0).
struct SfmKeypoint {
  float x = 0, y = 0;
  float size = 0;   // detector scale, pixels
  float angle = 0;  // degrees, -1 if the detector gives none
};

struct SfmImage {
  std::string frame;    // the scene's frame file, relative to the scene directory ("thermal/<t>.png")
  bool frozen = false;  // a NUC-frozen near-duplicate of the previous kept frame: not matched
  std::vector<SfmKeypoint> keypoints;
};

struct SfmObservation {
  uint32_t image = 0;     // index into SfmData::images (= the scene's frame index)
  uint32_t keypoint = 0;  // index into that image's keypoints
  bool operator==(const SfmObservation&) const = default;
};

struct SfmMatch {
  uint32_t keypoint_a = 0, keypoint_b = 0;
  bool inlier = false;  // passed geometric verification
};

// The mutual nearest-neighbour matches of one pair (image_a < image_b), verified or not.
struct SfmPairMatches {
  uint32_t image_a = 0, image_b = 0;
  std::vector<SfmMatch> matches;
};

struct SfmTrack {
  std::vector<SfmObservation> observations;  // at most one per image
  int64_t point = -1;                        // index into SfmData::points, -1: not triangulated
};

struct SfmPoint {
  Eigen::Vector3d xyz = Eigen::Vector3d::Zero();  // scene (recentred) world frame, metres
  double error_px = 0;                            // mean reprojection error over `observations`
  std::vector<SfmObservation> observations;       // the views that agree with the point (track length)
};

struct SfmData {
  std::vector<SfmImage> images;
  std::vector<SfmPairMatches> pairs;
  std::vector<SfmTrack> tracks;
  std::vector<SfmPoint> points;
};

// Writes images.txt, keypoints.txt, matches.txt, tracks.txt and points.txt into dir (created), each
// atomically, then frontend.json with `summary_json` last. std::invalid_argument on an inconsistent
// SfmData (an index out of range, a non-finite point); IoError on file errors.
void write_sfm(const std::filesystem::path& dir, const SfmData& data, const std::string& summary_json);

// Reads the five text files back. IoError naming the file and line on a wrong field count, a bad number,
// an index out of range or a non-finite coordinate.
SfmData read_sfm(const std::filesystem::path& dir);

// True if dir holds the files read_sfm reads.
bool has_sfm(const std::filesystem::path& dir);

}  // namespace litgs::io
