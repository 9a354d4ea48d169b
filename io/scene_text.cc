#include "io/scene_text.h"

#include <Eigen/Cholesky>
#include <cmath>

#include "io/atomic_file.h"
#include "io/error.h"
#include "io/text.h"

namespace litgs::io {
namespace {

const char* kImuHeader = "t,gyro_x,gyro_y,gyro_z,accel_x,accel_y,accel_z";

}  // namespace

std::vector<ImuSample> read_imu_csv(const std::filesystem::path& path) {
  LineReader reader(path);
  std::string line;
  bool header = true;
  std::vector<ImuSample> samples;
  while (reader.next(line)) {
    const int64_t n = reader.line_number();
    if (header) {
      if (trim(line) != kImuHeader) fail(path, n, std::string("expected the header '") + kImuHeader + "'");
      header = false;
      continue;
    }
    if (trim(line).empty()) continue;
    const auto f = split_char(line, ',');
    if (f.size() != 7) fail(path, n, "expected 7 comma-separated fields, got " + std::to_string(f.size()));
    static const char* names[7] = {"t", "gyro_x", "gyro_y", "gyro_z", "accel_x", "accel_y", "accel_z"};
    double v[7];
    for (int i = 0; i < 7; ++i) v[i] = parse_double(f[i], path, n, names[i]);
    ImuSample s{v[0], {v[1], v[2], v[3]}, {v[4], v[5], v[6]}};
    if (!samples.empty() && !(s.t_s > samples.back().t_s))
      fail(path, n,
           "timestamp " + format_double(s.t_s) + " is not greater than the previous " +
               format_double(samples.back().t_s));
    samples.push_back(s);
  }
  if (header) fail(path, 0, "empty file (expected the header line)");
  return samples;
}

void write_imu_csv(const std::filesystem::path& path, const std::vector<ImuSample>& samples) {
  write_file_atomic(path, [&](std::ostream& out) {
    out << kImuHeader << '\n';
    for (const auto& s : samples) {
      out << format_double(s.t_s);
      for (int i = 0; i < 3; ++i) out << ',' << format_double(s.gyro_rad_s[i]);
      for (int i = 0; i < 3; ++i) out << ',' << format_double(s.accel_m_s2[i]);
      out << '\n';
    }
  });
}

std::vector<Anchor> read_anchors(const std::filesystem::path& path) {
  LineReader reader(path);
  std::string line;
  std::vector<Anchor> anchors;
  while (reader.next(line)) {
    if (is_blank_or_comment(line)) continue;
    const int64_t n = reader.line_number();
    const auto f = split_ws(line);
    if (f.size() != 9)
      fail(path, n, "expected 9 fields 'x y z xx xy xz yy yz zz', got " + std::to_string(f.size()));
    static const char* names[9] = {"x", "y", "z", "xx", "xy", "xz", "yy", "yz", "zz"};
    double v[9];
    for (int i = 0; i < 9; ++i) v[i] = parse_double(f[i], path, n, names[i]);
    Anchor a;
    a.p_world = {v[0], v[1], v[2]};
    a.cov_m2 << v[3], v[4], v[5], v[4], v[6], v[7], v[5], v[7], v[8];
    // Cholesky succeeds exactly for symmetric positive definite matrices (a zero or negative pivot fails).
    const Eigen::LLT<Eigen::Matrix3d> llt(a.cov_m2);
    if (llt.info() != Eigen::Success || !(llt.matrixL().toDenseMatrix().diagonal().array() > 0).all())
      fail(path, n, "covariance is not positive definite");
    anchors.push_back(a);
  }
  return anchors;
}

void write_anchors(const std::filesystem::path& path, const std::vector<Anchor>& anchors) {
  write_file_atomic(path, [&](std::ostream& out) {
    out << "# x y z xx xy xz yy yz zz (metres, square metres)\n";
    for (const auto& a : anchors) {
      const Eigen::Matrix3d& c = a.cov_m2;
      const double v[9] = {a.p_world.x(), a.p_world.y(), a.p_world.z(), c(0, 0), c(0, 1),
                           c(0, 2),       c(1, 1),       c(1, 2),       c(2, 2)};
      for (int i = 0; i < 9; ++i) out << (i ? " " : "") << format_double(v[i]);
      out << '\n';
    }
  });
}

std::vector<Plane> read_planes(const std::filesystem::path& path) {
  LineReader reader(path);
  std::string line;
  std::vector<Plane> planes;
  while (reader.next(line)) {
    if (is_blank_or_comment(line)) continue;
    const int64_t n = reader.line_number();
    const auto f = split_ws(line);
    if (f.size() != 4) fail(path, n, "expected 4 fields 'nx ny nz d', got " + std::to_string(f.size()));
    Plane p;
    p.n = {parse_double(f[0], path, n, "nx"), parse_double(f[1], path, n, "ny"),
           parse_double(f[2], path, n, "nz")};
    p.d = parse_double(f[3], path, n, "d");
    if (std::abs(p.n.norm() - 1) > 1e-6)
      fail(path, n, "normal length is " + format_double(p.n.norm()) + ", not 1");
    planes.push_back(p);
  }
  return planes;
}

void write_planes(const std::filesystem::path& path, const std::vector<Plane>& planes) {
  write_file_atomic(path, [&](std::ostream& out) {
    out << "# nx ny nz d (n . x + d = 0, metres)\n";
    for (const auto& p : planes)
      out << format_double(p.n.x()) << ' ' << format_double(p.n.y()) << ' ' << format_double(p.n.z()) << ' '
          << format_double(p.d) << '\n';
  });
}

}  // namespace litgs::io
