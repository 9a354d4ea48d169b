// PLY point clouds: the "vertex" element of ascii, binary_little_endian and binary_big_endian files.
// x y z are required; nx ny nz become normals; intensity (or CloudCompare's scalar_intensity) becomes
// intensity; every other scalar vertex property goes to PointCloud::extra by name. Other elements (faces)
// are parsed past and dropped. (The standard 3DGS PLY is a different reader, not this one.)
#pragma once

#include <filesystem>

#include "io/point_cloud.h"

namespace litgs::io {

// IoError (file, line or byte offset, problem) on: a missing file, a bad magic or format line, an unknown
// property type, no vertex element or no x y z, truncated data, a wrong token count on an ascii line, a
// non-finite position or normal.
PointCloud read_ply_points(const std::filesystem::path& path);

}  // namespace litgs::io
