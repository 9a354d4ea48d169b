#include "io/ply_points.h"

#include <algorithm>
#include <cmath>

#include "io/error.h"
#include "io/file_bytes.h"
#include "io/scalar_type.h"
#include "io/text.h"

namespace litgs::io {
namespace {

struct Property {
  std::string name;
  ScalarType type = ScalarType::kF32;
  bool is_list = false;
  ScalarType count_type = ScalarType::kU8;  // lists only
};

struct Element {
  std::string name;
  size_t count = 0;
  std::vector<Property> properties;
};

enum class Format { kAscii, kLittle, kBig };

bool to_type(std::string_view s, ScalarType& t) {
  static const std::pair<const char*, ScalarType> names[] = {
      {"char", ScalarType::kI8},    {"int8", ScalarType::kI8},     {"uchar", ScalarType::kU8},
      {"uint8", ScalarType::kU8},   {"short", ScalarType::kI16},   {"int16", ScalarType::kI16},
      {"ushort", ScalarType::kU16}, {"uint16", ScalarType::kU16},  {"int", ScalarType::kI32},
      {"int32", ScalarType::kI32},  {"uint", ScalarType::kU32},    {"uint32", ScalarType::kU32},
      {"float", ScalarType::kF32},  {"float32", ScalarType::kF32}, {"double", ScalarType::kF64},
      {"float64", ScalarType::kF64}};
  for (const auto& [n, type] : names)
    if (s == n) {
      t = type;
      return true;
    }
  return false;
}

}  // namespace

PointCloud read_ply_points(const std::filesystem::path& path) {
  const std::string bytes = read_file_bytes(path);
  std::vector<Element> elements;
  Format format = Format::kAscii;
  bool have_format = false;
  size_t pos = 0;
  int64_t line_no = 0;
  while (true) {
    const size_t end = bytes.find('\n', pos);
    if (end == std::string::npos) fail(path, line_no + 1, "the header ends before end_header");
    std::string line = bytes.substr(pos, end - pos);
    if (!line.empty() && line.back() == '\r') line.pop_back();
    ++line_no;
    pos = end + 1;
    const auto t = split_ws(line);
    if (line_no == 1) {
      if (line != "ply") fail(path, 1, "not a PLY file (the first line is not 'ply')");
      continue;
    }
    if (t.empty()) continue;
    if (t[0] == "comment" || t[0] == "obj_info") continue;
    if (t[0] == "end_header") break;
    if (t[0] == "format") {
      if (t.size() != 3) fail(path, line_no, "expected 'format KIND 1.0'");
      if (t[1] == "ascii")
        format = Format::kAscii;
      else if (t[1] == "binary_little_endian")
        format = Format::kLittle;
      else if (t[1] == "binary_big_endian")
        format = Format::kBig;
      else
        fail(path, line_no, "unknown format '" + std::string(t[1]) + "'");
      have_format = true;
    } else if (t[0] == "element") {
      if (t.size() != 3) fail(path, line_no, "expected 'element NAME COUNT'");
      elements.push_back(
          {std::string(t[1]),
           static_cast<size_t>(parse_int(t[2], path, line_no, "element count", 0, int64_t{1} << 40)),
           {}});
    } else if (t[0] == "property") {
      if (elements.empty()) fail(path, line_no, "property before any element");
      Property p;
      if (t.size() == 5 && t[1] == "list") {
        p.is_list = true;
        if (!to_type(t[2], p.count_type) || !to_type(t[3], p.type))
          fail(path, line_no,
               "unknown list property types '" + std::string(t[2]) + " " + std::string(t[3]) + "'");
        p.name = t[4];
      } else if (t.size() == 3) {
        if (!to_type(t[1], p.type)) fail(path, line_no, "unknown property type '" + std::string(t[1]) + "'");
        p.name = t[2];
      } else {
        fail(path, line_no, "expected 'property TYPE NAME' or 'property list COUNT_TYPE TYPE NAME'");
      }
      elements.back().properties.push_back(p);
    } else {
      fail(path, line_no, "unknown header keyword '" + std::string(t[0]) + "'");
    }
  }
  if (!have_format) fail(path, line_no, "no format line in the header");
  const int64_t header_lines = line_no;

  PointCloud cloud;
  bool found_vertex = false;
  const auto* data = reinterpret_cast<const unsigned char*>(bytes.data());
  std::vector<double> values;
  for (const Element& el : elements) {
    const bool is_vertex = el.name == "vertex";
    int ix = -1, iy = -1, iz = -1, inx = -1, iny = -1, inz = -1, ii = -1;
    std::vector<int> extra;
    if (is_vertex) {
      found_vertex = true;
      for (int k = 0; k < static_cast<int>(el.properties.size()); ++k) {
        const Property& p = el.properties[k];
        if (p.is_list) continue;
        if (p.name == "x")
          ix = k;
        else if (p.name == "y")
          iy = k;
        else if (p.name == "z")
          iz = k;
        else if (p.name == "nx")
          inx = k;
        else if (p.name == "ny")
          iny = k;
        else if (p.name == "nz")
          inz = k;
        else if (p.name == "intensity" || (p.name == "scalar_intensity" && ii < 0))
          ii = k;
        else
          extra.push_back(k);
      }
      if (ix < 0 || iy < 0 || iz < 0) fail(path, header_lines, "the vertex element lacks one of x y z");
      const int normals = (inx >= 0) + (iny >= 0) + (inz >= 0);
      if (normals != 0 && normals != 3) fail(path, header_lines, "nx ny nz must come together");
      const size_t expected = std::min(el.count, bytes.size());  // a forged count must not allocate terabytes
      cloud.positions.reserve(expected);
      if (ii >= 0) cloud.intensity.reserve(expected);
      for (int k : extra) cloud.extra.push_back({el.properties[k].name, {}});
    }
    values.assign(el.properties.size(), 0.0);
    for (size_t i = 0; i < el.count; ++i) {
      if (format == Format::kAscii) {
        std::string_view line;
        do {
          if (pos >= bytes.size())
            fail(path, line_no + 1,
                 "truncated: element '" + el.name + "' has " + std::to_string(el.count) + " entries, " +
                     std::to_string(i) + " present");
          size_t end = bytes.find('\n', pos);
          if (end == std::string::npos) end = bytes.size();
          line = std::string_view(bytes).substr(pos, end - pos);
          pos = end + 1;
          ++line_no;
        } while (trim(line).empty());
        const auto t = split_ws(trim(line));
        size_t tok = 0;
        for (size_t k = 0; k < el.properties.size(); ++k) {
          const Property& p = el.properties[k];
          if (tok >= t.size()) fail(path, line_no, "too few values for element '" + el.name + "'");
          if (p.is_list) {
            const int64_t n = parse_int(t[tok++], path, line_no, p.name + " count", 0, 1 << 20);
            tok += static_cast<size_t>(n);
          } else {
            values[k] = parse_double(t[tok++], path, line_no, p.name);
          }
        }
        if (tok != t.size())
          fail(path, line_no, "expected " + std::to_string(tok) + " values, got " + std::to_string(t.size()));
      } else {
        const bool big = format == Format::kBig;
        for (size_t k = 0; k < el.properties.size(); ++k) {
          const Property& p = el.properties[k];
          const auto need = [&](size_t n) {
            if (pos + n > bytes.size())
              fail_at_byte(path, pos,
                           "truncated: element '" + el.name + "' entry " + std::to_string(i) + " of " +
                               std::to_string(el.count) + " runs past the end of the file");
          };
          if (p.is_list) {
            need(scalar_size(p.count_type));
            const double n = read_scalar(data + pos, p.count_type, big);
            pos += scalar_size(p.count_type);
            if (!(n >= 0) || n > static_cast<double>(bytes.size()))
              fail_at_byte(path, pos, "list length " + format_double(n) + " is impossible");
            need(static_cast<size_t>(n) * scalar_size(p.type));
            pos += static_cast<size_t>(n) * scalar_size(p.type);
          } else {
            need(scalar_size(p.type));
            values[k] = read_scalar(data + pos, p.type, big);
            pos += scalar_size(p.type);
          }
        }
      }
      if (!is_vertex) continue;
      const Eigen::Vector3d p(values[ix], values[iy], values[iz]);
      if (!p.allFinite()) {
        if (format == Format::kAscii) fail(path, line_no, "non-finite position");
        fail(path, 0, "vertex " + std::to_string(i) + ": non-finite position");
      }
      cloud.positions.push_back(p);
      if (ii >= 0) cloud.intensity.push_back(static_cast<float>(values[ii]));
      if (inx >= 0) {
        const Eigen::Vector3f n(static_cast<float>(values[inx]), static_cast<float>(values[iny]),
                                static_cast<float>(values[inz]));
        if (!n.allFinite())
          fail(path, format == Format::kAscii ? line_no : 0,
               "vertex " + std::to_string(i) + ": non-finite normal");
        cloud.normals.push_back(n);
      }
      for (size_t e = 0; e < extra.size(); ++e) cloud.extra[e].values.push_back(values[extra[e]]);
    }
  }
  if (!found_vertex) fail(path, header_lines, "no vertex element");
  return cloud;
}

}  // namespace litgs::io
