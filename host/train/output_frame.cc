#include "host/train/output_frame.h"

#include <cmath>
#include <cstdio>
#include <sstream>

#include "io/error.h"
#include "io/gaussian_ply.h"

namespace litgs::host {
namespace {

constexpr const char* kWorldOffset = "litgs_world_offset_m";
constexpr const char* kSceneOffset = "litgs_scene_world_offset_m";

std::string vector_text(const Eigen::Vector3d& v) {
  char buf[96];
  std::snprintf(buf, sizeof buf, "%.17g %.17g %.17g", v.x(), v.y(), v.z());
  return buf;
}

// "NAME X Y Z" -> (X, Y, Z) if the comment is NAME; IoError if its values do not parse.
std::optional<Eigen::Vector3d> parse_vector(const std::filesystem::path& path, const std::string& comment,
                                            const std::string& name) {
  std::istringstream s(comment);
  std::string key;
  s >> key;
  if (key != name) return std::nullopt;
  Eigen::Vector3d v;
  std::string rest;
  if (!(s >> v.x() >> v.y() >> v.z()) || (s >> rest) || !v.allFinite())
    io::fail(
        path, 0,
        "header line 'comment " + comment + "': expected '" + name + " X Y Z' with three finite numbers");
  return v;
}

}  // namespace

std::vector<std::string> model_frame_comments(const ModelFrame& f) {
  std::vector<std::string> c = {std::string(kWorldOffset) + " " + vector_text(f.world_offset_m)};
  if (f.scene_world_offset_m)
    c.push_back(std::string(kSceneOffset) + " " + vector_text(*f.scene_world_offset_m));
  return c;
}

ModelFrame read_model_frame(const std::filesystem::path& ply) {
  ModelFrame f;
  for (const std::string& c : io::read_gaussian_ply_comments(ply)) {
    if (auto v = parse_vector(ply, c, kWorldOffset)) f.world_offset_m = *v;
    if (auto v = parse_vector(ply, c, kSceneOffset)) f.scene_world_offset_m = *v;
  }
  return f;
}

kernels::GaussianModel shift_means(kernels::GaussianModel m, const Eigen::Vector3d& delta) {
  for (int a = 0; a < 3; ++a) {
    if (delta[a] == 0.0) continue;
    for (size_t i = 0; i < m.size(); ++i)
      m.means[3 * i + a] = static_cast<float>(static_cast<double>(m.means[3 * i + a]) + delta[a]);
  }
  return m;
}

}  // namespace litgs::host
