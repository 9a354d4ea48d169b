// PCD point clouds (the Point Cloud Library's format) with a small parser of our own: no PCL anywhere.
// Reads DATA ascii, binary and binary_compressed (LZF); fields x y z (required), intensity, normal_x/y/z,
// any other single-count field into PointCloud::extra; multi-count fields (descriptors) and "_" padding are
// skipped. Writes binary.
#pragma once

#include <filesystem>

#include "io/point_cloud.h"

namespace litgs::io {

struct PcdReadOptions {
  // Organized clouds mark missing returns with NaN positions. false: such a point is an IoError naming it;
  // true: it is dropped (with all its attributes).
  bool drop_nonfinite_points = false;
};

// IoError (file, line or byte offset, problem) on: a missing file, a malformed or inconsistent header
// (field/size/type/count lengths, WIDTH*HEIGHT != POINTS, missing x y z, an unknown DATA kind), a
// non-identity VIEWPOINT, truncated data, a bad LZF stream, a wrong token count on an ascii line, a
// non-finite position, normal or intensity (unless dropped).
PointCloud read_pcd(const std::filesystem::path& path, const PcdReadOptions& options = {});

struct PcdWriteOptions {
  // false: x y z as float32 (what PCL's PointXYZ reads; ~6e-5 m steps at 1000 m); true: float64 (exact).
  bool double_positions = false;
};

// Writes DATA binary, atomically: x y z, then intensity (F4), normal_x/y/z (F4), extra fields (F8) if
// present.
void write_pcd(const std::filesystem::path& path, const PointCloud& cloud,
               const PcdWriteOptions& options = {});

}  // namespace litgs::io
