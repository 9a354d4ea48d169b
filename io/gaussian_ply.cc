#include "io/gaussian_ply.h"

#include <bit>
#include <cstring>
#include <fstream>
#include <stdexcept>
#include <string>
#include <vector>

#include "io/atomic_file.h"
#include "io/error.h"
#include "io/ply_points.h"

namespace litgs::io {
namespace {

// Whether the header carries "comment litgs_channels 1".
bool header_says_one_channel(const std::filesystem::path& path) {
  std::ifstream in(path, std::ios::binary);
  std::string line;
  for (int i = 0; i < 1000 && std::getline(in, line); ++i) {
    if (!line.empty() && line.back() == '\r') line.pop_back();
    if (line == "end_header") break;
    if (line == "comment litgs_channels 1") return true;
  }
  return false;
}

uint32_t degree_for_rest(const std::filesystem::path& path, size_t rest) {
  for (uint32_t d = 0; d <= 3; ++d)
    if (rest == 3 * ((d + 1) * (d + 1) - 1)) return d;
  fail(path, 0, "3DGS PLY has " + std::to_string(rest) + " f_rest_* properties; expected 0, 9, 24 or 45");
}

}  // namespace

kernels::GaussianModel read_gaussian_ply(const std::filesystem::path& path) {
  const PointCloud cloud = read_ply_points(path);
  auto field = [&](const std::string& name) -> const std::vector<double>& {
    const ScalarField* f = cloud.field(name);
    if (!f) fail(path, 0, "3DGS PLY lacks the vertex property '" + name + "'");
    return f->values;
  };
  size_t rest = 0;
  while (cloud.field("f_rest_" + std::to_string(rest))) ++rest;
  kernels::GaussianModel m;
  m.sh_degree = degree_for_rest(path, rest);
  const bool one = header_says_one_channel(path);
  m.channels = one ? 1 : 3;
  const size_t n = cloud.size();
  m.resize(n);
  const uint32_t K = m.sh_coeffs();
  const auto& opacity = field("opacity");
  const std::vector<double>* scale[3] = {&field("scale_0"), &field("scale_1"), &field("scale_2")};
  const std::vector<double>* rot[4] = {&field("rot_0"), &field("rot_1"), &field("rot_2"), &field("rot_3")};
  const std::vector<double>* dc[3] = {&field("f_dc_0"), &field("f_dc_1"), &field("f_dc_2")};
  std::vector<const std::vector<double>*> rest_fields;
  for (size_t r = 0; r < rest; ++r) rest_fields.push_back(&field("f_rest_" + std::to_string(r)));
  for (size_t i = 0; i < n; ++i) {
    for (int a = 0; a < 3; ++a) {
      m.means[3 * i + a] = static_cast<float>(cloud.positions[i][a]);
      m.log_scales[3 * i + a] = static_cast<float>((*scale[a])[i]);
    }
    for (int a = 0; a < 4; ++a) m.quats[4 * i + a] = static_cast<float>((*rot[a])[i]);
    m.opacity_logits[i] = static_cast<float>(opacity[i]);
    for (uint32_t c = 0; c < m.channels; ++c) {
      m.sh[(i * K) * m.channels + c] = static_cast<float>((*dc[c])[i]);
      for (uint32_t k = 1; k < K; ++k)
        m.sh[(i * K + k) * m.channels + c] = static_cast<float>((*rest_fields[c * (K - 1) + (k - 1)])[i]);
    }
    if (one && ((*dc[1])[i] != (*dc[0])[i] || (*dc[2])[i] != (*dc[0])[i]))
      fail(path, 0,
           "vertex " + std::to_string(i) +
               " has different f_dc_0..2 but the header says litgs_channels 1 (a gray model)");
  }
  return m;
}

std::vector<std::string> read_gaussian_ply_comments(const std::filesystem::path& path) {
  std::ifstream in(path, std::ios::binary);
  if (!in) fail(path, 0, "cannot open the file");
  std::vector<std::string> comments;
  std::string line;
  for (int i = 1; i <= 1000 && std::getline(in, line); ++i) {
    if (!line.empty() && line.back() == '\r') line.pop_back();
    if (i == 1 && line != "ply") fail(path, 1, "not a PLY file (no 'ply' line)");
    if (line == "end_header") return comments;
    if (line.rfind("comment ", 0) == 0) comments.push_back(line.substr(8));
  }
  fail(path, 0, "PLY header without end_header in its first 1000 lines");
}

void write_gaussian_ply(const std::filesystem::path& path, const kernels::GaussianModel& m,
                        const std::vector<std::string>& comments) {
  m.check();
  for (const auto& c : comments)
    if (c.find_first_of("\r\n") != std::string::npos)
      throw std::invalid_argument("write_gaussian_ply: a header comment holds a line break: '" + c + "'");
  if (m.channels != 1 && m.channels != 3)
    throw std::invalid_argument("write_gaussian_ply: the 3DGS PLY holds 1 (as gray) or 3 channels, not " +
                                std::to_string(m.channels));
  const size_t n = m.size();
  const uint32_t K = m.sh_coeffs(), C = m.channels;
  write_file_atomic(path, [&](std::ostream& out) {
    out << "ply\nformat binary_little_endian 1.0\n";
    if (C == 1) out << "comment litgs_channels 1\n";
    for (const auto& c : comments) out << "comment " << c << "\n";
    out << "element vertex " << n << "\n";
    for (const char* p : {"x", "y", "z", "nx", "ny", "nz", "f_dc_0", "f_dc_1", "f_dc_2"})
      out << "property float " << p << "\n";
    for (uint32_t r = 0; r < 3 * (K - 1); ++r) out << "property float f_rest_" << r << "\n";
    for (const char* p : {"opacity", "scale_0", "scale_1", "scale_2", "rot_0", "rot_1", "rot_2", "rot_3"})
      out << "property float " << p << "\n";
    out << "end_header\n";
    std::vector<float> row;
    for (size_t i = 0; i < n; ++i) {
      row.clear();
      for (int a = 0; a < 3; ++a) row.push_back(m.means[3 * i + a]);
      row.insert(row.end(), {0.0f, 0.0f, 0.0f});
      for (uint32_t c = 0; c < 3; ++c) row.push_back(m.sh[(i * K) * C + (C == 1 ? 0 : c)]);
      for (uint32_t c = 0; c < 3; ++c)
        for (uint32_t k = 1; k < K; ++k) row.push_back(m.sh[(i * K + k) * C + (C == 1 ? 0 : c)]);
      row.push_back(m.opacity_logits[i]);
      for (int a = 0; a < 3; ++a) row.push_back(m.log_scales[3 * i + a]);
      for (int a = 0; a < 4; ++a) row.push_back(m.quats[4 * i + a]);
      // The PLY is little-endian; so is every machine this engine targets (checked at compile time).
      static_assert(std::endian::native == std::endian::little);
      out.write(reinterpret_cast<const char*>(row.data()),
                static_cast<std::streamsize>(row.size() * sizeof(float)));
    }
  });
}

}  // namespace litgs::io
