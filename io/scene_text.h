// The scene directory's small text files: imu.csv, anchors.txt, planes.txt. Strict readers (IoError with
// file, line and problem), atomic writers with round-trip exact numbers.
#pragma once

#include <filesystem>
#include <vector>

#include "io/scene_types.h"

namespace litgs::io {

// imu.csv: the header line "t,gyro_x,gyro_y,gyro_z,accel_x,accel_y,accel_z", then one sample per line
// (s, rad/s, m/s^2), timestamps strictly increasing.
std::vector<ImuSample> read_imu_csv(const std::filesystem::path& path);
void write_imu_csv(const std::filesystem::path& path, const std::vector<ImuSample>& samples);

// anchors.txt: "x y z xx xy xz yy yz zz" per line ('#' comments), covariance positive definite.
std::vector<Anchor> read_anchors(const std::filesystem::path& path);
void write_anchors(const std::filesystem::path& path, const std::vector<Anchor>& anchors);

// planes.txt: "nx ny nz d" per line ('#' comments), |n| = 1 within 1e-6 (kept as written).
std::vector<Plane> read_planes(const std::filesystem::path& path);
void write_planes(const std::filesystem::path& path, const std::vector<Plane>& planes);

}  // namespace litgs::io
