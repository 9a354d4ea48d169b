#include "io/tum.h"

#include <algorithm>
#include <cmath>

#include "io/atomic_file.h"
#include "io/error.h"
#include "io/text.h"

namespace litgs::io {

std::vector<TumPose> read_tum(const std::filesystem::path& path, const TumReadOptions& options) {
  LineReader reader(path);
  std::vector<TumPose> poses;
  std::string line;
  while (reader.next(line)) {
    if (is_blank_or_comment(line)) continue;
    const int64_t n = reader.line_number();
    const auto f = split_ws(line);
    if (f.size() != 8)
      fail(path, n, "expected 8 fields 't x y z qx qy qz qw', got " + std::to_string(f.size()));
    static const char* names[8] = {"t", "x", "y", "z", "qx", "qy", "qz", "qw"};
    double v[8];
    for (int i = 0; i < 8; ++i) v[i] = parse_double(f[i], path, n, names[i]);
    TumPose pose;
    pose.t_s = v[0];
    pose.p_world = {v[1], v[2], v[3]};
    if (v[4] == 0 && v[5] == 0 && v[6] == 0 && v[7] == 0) {
      pose.has_rotation =
          false;  // unknown rotation: keep identity storage, never normalize a zero quaternion
    } else {
      const Eigen::Quaterniond q(v[7], v[4], v[5], v[6]);
      const double norm = q.norm();
      if (std::abs(norm - 1.0) > options.quaternion_norm_tolerance)
        fail(path, n, "quaternion norm is " + format_double(norm) + ", not 1 (and not the unknown 0 0 0 0)");
      pose.q_world_body = q.normalized();
    }
    if (options.require_increasing_time && !poses.empty() && !(pose.t_s > poses.back().t_s))
      fail(path, n,
           "timestamp " + format_double(pose.t_s) + " is not greater than the previous " +
               format_double(poses.back().t_s));
    poses.push_back(pose);
  }
  return poses;
}

std::optional<Eigen::Matrix4d> tum_pose_at(const std::vector<TumPose>& poses, double t, double snap_s) {
  const auto matrix = [](const Eigen::Quaterniond& q, const Eigen::Vector3d& p) {
    Eigen::Matrix4d T = Eigen::Matrix4d::Identity();
    T.topLeftCorner<3, 3>() = q.toRotationMatrix();
    T.topRightCorner<3, 1>() = p;
    return T;
  };
  const auto it =
      std::lower_bound(poses.begin(), poses.end(), t, [](const TumPose& p, double x) { return p.t_s < x; });
  // The nearest pose within snap_s (it, or the one before it).
  for (auto c : {it, it == poses.begin() ? poses.end() : it - 1})
    if (c != poses.end() && std::abs(c->t_s - t) <= snap_s) {
      if (!c->has_rotation) return std::nullopt;
      return matrix(c->q_world_body, c->p_world);
    }
  if (it == poses.end() || it == poses.begin()) return std::nullopt;
  const TumPose& a = *(it - 1);
  const TumPose& b = *it;
  if (!a.has_rotation || !b.has_rotation) return std::nullopt;
  const double s = (t - a.t_s) / (b.t_s - a.t_s);
  return matrix(a.q_world_body.slerp(s, b.q_world_body), (1 - s) * a.p_world + s * b.p_world);
}

void write_tum(const std::filesystem::path& path, const std::vector<TumPose>& poses) {
  write_file_atomic(path, [&](std::ostream& out) {
    out << "# t x y z qx qy qz qw\n";
    for (const TumPose& p : poses) {
      out << format_double(p.t_s) << ' ' << format_double(p.p_world.x()) << ' '
          << format_double(p.p_world.y()) << ' ' << format_double(p.p_world.z()) << ' ';
      if (p.has_rotation) {
        const Eigen::Quaterniond& q = p.q_world_body;
        out << format_double(q.x()) << ' ' << format_double(q.y()) << ' ' << format_double(q.z()) << ' '
            << format_double(q.w()) << '\n';
      } else {
        out << "0 0 0 0\n";
      }
    }
  });
}

}  // namespace litgs::io
