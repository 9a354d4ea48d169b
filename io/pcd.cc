#include "io/pcd.h"

#include <algorithm>
#include <charconv>
#include <cmath>
#include <cstring>
#include <optional>

#include "io/atomic_file.h"
#include "io/error.h"
#include "io/file_bytes.h"
#include "io/lzf.h"
#include "io/scalar_type.h"
#include "io/text.h"

namespace litgs::io {
namespace {

struct Field {
  std::string name;
  size_t size = 0;
  char type = 0;  // F, I or U
  size_t count = 1;
  ScalarType scalar = ScalarType::kF32;
  size_t offset = 0;  // bytes from the start of a point (binary), or first token index (ascii)
};

enum class DataKind { kAscii, kBinary, kBinaryCompressed };

ScalarType to_scalar(const std::filesystem::path& path, int64_t line, const Field& f) {
  if (f.type == 'F' && f.size == 4) return ScalarType::kF32;
  if (f.type == 'F' && f.size == 8) return ScalarType::kF64;
  if (f.type == 'I' || f.type == 'U') {
    const bool u = f.type == 'U';
    switch (f.size) {
      case 1:
        return u ? ScalarType::kU8 : ScalarType::kI8;
      case 2:
        return u ? ScalarType::kU16 : ScalarType::kI16;
      case 4:
        return u ? ScalarType::kU32 : ScalarType::kI32;
      case 8:
        return u ? ScalarType::kU64 : ScalarType::kI64;
    }
  }
  fail(path, line,
       "field '" + f.name + "': unsupported TYPE " + std::string(1, f.type) + " with SIZE " +
           std::to_string(f.size));
}

struct Header {
  std::vector<Field> fields;
  size_t points = 0;
  size_t stride = 0;  // bytes per point (binary)
  size_t tokens = 0;  // values per point (ascii)
  DataKind kind = DataKind::kAscii;
  size_t data_offset = 0;  // first byte after the DATA line
  int64_t data_line = 0;   // line number of the DATA line
};

Header parse_header(const std::filesystem::path& path, const std::string& bytes) {
  Header h;
  std::vector<std::string> names, types;
  std::vector<size_t> sizes, counts;
  int64_t fields_line = 0, sizes_line = 0, types_line = 0, counts_line = 0;
  std::optional<size_t> width, height, points;
  size_t pos = 0;
  int64_t line_no = 0;
  while (true) {
    const size_t end = bytes.find('\n', pos);
    if (end == std::string::npos) fail(path, line_no + 1, "the header ends before a DATA line");
    std::string line = bytes.substr(pos, end - pos);
    if (!line.empty() && line.back() == '\r') line.pop_back();
    ++line_no;
    pos = end + 1;
    if (is_blank_or_comment(line)) continue;
    const auto t = split_ws(line);
    const std::string key(t[0]);
    const auto count_values = [&](size_t n) {
      if (t.size() != n + 1)
        fail(path, line_no,
             key + ": expected " + std::to_string(n) + " values, got " + std::to_string(t.size() - 1));
    };
    const auto as_size = [&](std::string_view s, const char* what) {
      return static_cast<size_t>(parse_int(s, path, line_no, what, 0, int64_t{1} << 40));
    };
    if (key == "VERSION") {
      continue;
    } else if (key == "FIELDS") {
      fields_line = line_no;
      for (size_t i = 1; i < t.size(); ++i) names.emplace_back(t[i]);
    } else if (key == "SIZE") {
      sizes_line = line_no;
      for (size_t i = 1; i < t.size(); ++i) sizes.push_back(as_size(t[i], "SIZE"));
    } else if (key == "TYPE") {
      types_line = line_no;
      for (size_t i = 1; i < t.size(); ++i) types.emplace_back(t[i]);
    } else if (key == "COUNT") {
      counts_line = line_no;
      for (size_t i = 1; i < t.size(); ++i)
        counts.push_back(static_cast<size_t>(parse_int(t[i], path, line_no, "COUNT", 0, 1 << 20)));
    } else if (key == "WIDTH") {
      count_values(1);
      width = as_size(t[1], "WIDTH");
    } else if (key == "HEIGHT") {
      count_values(1);
      height = as_size(t[1], "HEIGHT");
    } else if (key == "POINTS") {
      count_values(1);
      points = as_size(t[1], "POINTS");
    } else if (key == "VIEWPOINT") {
      count_values(7);
      static const double identity[7] = {0, 0, 0, 1, 0, 0, 0};
      for (int i = 0; i < 7; ++i)
        if (parse_double(t[i + 1], path, line_no, "VIEWPOINT") != identity[i])
          fail(path, line_no, "a non-identity VIEWPOINT is not supported (transform the cloud instead)");
    } else if (key == "DATA") {
      count_values(1);
      if (t[1] == "ascii")
        h.kind = DataKind::kAscii;
      else if (t[1] == "binary")
        h.kind = DataKind::kBinary;
      else if (t[1] == "binary_compressed")
        h.kind = DataKind::kBinaryCompressed;
      else
        fail(path, line_no,
             "unknown DATA kind '" + std::string(t[1]) + "' (ascii, binary, binary_compressed)");
      h.data_offset = pos;
      h.data_line = line_no;
      break;
    } else {
      fail(path, line_no, "unknown header key '" + key + "'");
    }
  }
  if (names.empty()) fail(path, h.data_line, "no FIELDS line before DATA");
  if (sizes.size() != names.size())
    fail(path, sizes_line ? sizes_line : h.data_line,
         "SIZE has " + std::to_string(sizes.size()) + " entries for " + std::to_string(names.size()) +
             " FIELDS");
  if (types.size() != names.size())
    fail(path, types_line ? types_line : h.data_line,
         "TYPE has " + std::to_string(types.size()) + " entries for " + std::to_string(names.size()) +
             " FIELDS");
  if (counts.empty()) counts.assign(names.size(), 1);
  if (counts.size() != names.size())
    fail(path, counts_line,
         "COUNT has " + std::to_string(counts.size()) + " entries for " + std::to_string(names.size()) +
             " FIELDS");
  if (!width || !height) fail(path, h.data_line, "WIDTH and HEIGHT are required before DATA");
  h.points = points ? *points : *width * *height;
  if (*width * *height != h.points)
    fail(path, h.data_line,
         "WIDTH*HEIGHT = " + std::to_string(*width * *height) + " but POINTS = " + std::to_string(h.points));
  for (size_t i = 0; i < names.size(); ++i) {
    Field f;
    f.name = names[i];
    f.size = sizes[i];
    if (types[i].size() != 1) fail(path, types_line, "TYPE '" + types[i] + "' is not one of F I U");
    f.type = types[i][0];
    f.count = counts[i];
    if (f.count == 0) fail(path, counts_line, "field '" + f.name + "' has COUNT 0");
    f.scalar = to_scalar(path, types_line, f);
    f.offset = h.kind == DataKind::kAscii ? h.tokens : h.stride;
    h.stride += f.size * f.count;
    h.tokens += f.count;
    h.fields.push_back(f);
  }
  (void)fields_line;
  return h;
}

// Indices into Header::fields of the attributes we keep; -1 when absent.
struct Layout {
  int x = -1, y = -1, z = -1, intensity = -1, nx = -1, ny = -1, nz = -1;
  std::vector<int> extra;
};

Layout make_layout(const std::filesystem::path& path, const Header& h) {
  Layout l;
  for (int i = 0; i < static_cast<int>(h.fields.size()); ++i) {
    const Field& f = h.fields[i];
    if (f.count != 1) continue;  // descriptors and padding arrays
    if (f.name == "x")
      l.x = i;
    else if (f.name == "y")
      l.y = i;
    else if (f.name == "z")
      l.z = i;
    else if (f.name == "intensity")
      l.intensity = i;
    else if (f.name == "normal_x")
      l.nx = i;
    else if (f.name == "normal_y")
      l.ny = i;
    else if (f.name == "normal_z")
      l.nz = i;
    else if (f.name != "_")
      l.extra.push_back(i);
  }
  if (l.x < 0 || l.y < 0 || l.z < 0) fail(path, h.data_line, "FIELDS lacks one of x y z (with COUNT 1)");
  const int normals = (l.nx >= 0) + (l.ny >= 0) + (l.nz >= 0);
  if (normals != 0 && normals != 3) fail(path, h.data_line, "normal_x normal_y normal_z must come together");
  return l;
}

}  // namespace

PointCloud read_pcd(const std::filesystem::path& path, const PcdReadOptions& options) {
  const std::string bytes = read_file_bytes(path);
  const Header h = parse_header(path, bytes);
  const Layout l = make_layout(path, h);
  const size_t nf = h.fields.size();
  const auto* data = reinterpret_cast<const unsigned char*>(bytes.data()) + h.data_offset;
  const size_t data_size = bytes.size() - h.data_offset;

  // Per-field base pointer and per-point step for the binary layouts.
  std::vector<const unsigned char*> base(nf);
  std::vector<size_t> step(nf);
  std::string decompressed;
  if (h.kind == DataKind::kBinary) {
    if (h.points > data_size / h.stride)  // (division: a forged POINTS must not overflow the product)
      fail_at_byte(path, h.data_offset,
                   "truncated: " + std::to_string(h.points) + " points of " + std::to_string(h.stride) +
                       " bytes need " + std::to_string(h.points * h.stride) +
                       " bytes of data, the file has " + std::to_string(data_size));
    for (size_t f = 0; f < nf; ++f) base[f] = data + h.fields[f].offset, step[f] = h.stride;
  } else if (h.kind == DataKind::kBinaryCompressed) {
    if (data_size < 8) fail_at_byte(path, h.data_offset, "truncated: no compressed-size words after DATA");
    uint32_t compressed = 0, uncompressed = 0;
    std::memcpy(&compressed, data, 4);
    std::memcpy(&uncompressed, data + 4, 4);
    if (h.points > 0xFFFFFFFFu / h.stride || uncompressed != h.points * h.stride)
      fail_at_byte(path, h.data_offset + 4,
                   "uncompressed size " + std::to_string(uncompressed) + " differs from POINTS*point size " +
                       std::to_string(h.points * h.stride));
    if (data_size - 8 < compressed)
      fail_at_byte(path, h.data_offset + 8,
                   "truncated: " + std::to_string(compressed) + " compressed bytes announced, " +
                       std::to_string(data_size - 8) + " present");
    decompressed.resize(uncompressed);
    const std::string problem = lzf_decompress(
        data + 8, compressed, reinterpret_cast<unsigned char*>(decompressed.data()), uncompressed);
    if (!problem.empty()) fail_at_byte(path, h.data_offset + 8, "corrupt LZF data: " + problem);
    // binary_compressed stores fields one after the other (all x, then all y, ...).
    const auto* d = reinterpret_cast<const unsigned char*>(decompressed.data());
    size_t offset = 0;
    for (size_t f = 0; f < nf; ++f) {
      base[f] = d + offset;
      step[f] = h.fields[f].size * h.fields[f].count;
      offset += step[f] * h.points;
    }
  }

  PointCloud cloud;
  // An ascii point takes at least two bytes per value: never trust POINTS for the allocation alone.
  const size_t expected =
      h.kind == DataKind::kAscii ? std::min(h.points, data_size / (2 * h.tokens) + 1) : h.points;
  cloud.positions.reserve(expected);
  if (l.intensity >= 0) cloud.intensity.reserve(expected);
  if (l.nx >= 0) cloud.normals.reserve(expected);
  for (int e : l.extra) cloud.extra.push_back({h.fields[e].name, {}});

  std::vector<double> v(nf);
  std::vector<double> ascii_values(h.tokens);
  size_t pos = 0;  // ascii: offset of the next line within data
  int64_t line_no = h.data_line;
  for (size_t i = 0; i < h.points; ++i) {
    std::string where;
    if (h.kind == DataKind::kAscii) {
      std::string_view line;
      do {
        if (pos >= data_size)
          fail(path, line_no + 1,
               "truncated: " + std::to_string(h.points) + " points announced, " + std::to_string(i) +
                   " present");
        size_t end = bytes.find('\n', h.data_offset + pos);
        if (end == std::string::npos) end = bytes.size();
        line = std::string_view(bytes).substr(h.data_offset + pos, end - h.data_offset - pos);
        pos = end + 1 - h.data_offset;
        ++line_no;
      } while (trim(line).empty());
      const auto t = split_ws(trim(line));
      if (t.size() != h.tokens)
        fail(path, line_no,
             "expected " + std::to_string(h.tokens) + " values, got " + std::to_string(t.size()));
      for (size_t f = 0; f < nf; ++f) {
        const std::string_view tok = t[h.fields[f].offset];
        const auto [ptr, ec] = std::from_chars(tok.data(), tok.data() + tok.size(), v[f]);  // accepts nan
        if (ec != std::errc() || ptr != tok.data() + tok.size())
          fail(path, line_no, "field '" + h.fields[f].name + "': not a number: '" + std::string(tok) + "'");
      }
    } else {
      for (size_t f = 0; f < nf; ++f) v[f] = read_scalar(base[f] + i * step[f], h.fields[f].scalar, false);
    }
    const auto bad = [&](const std::string& problem) {
      if (h.kind == DataKind::kAscii) fail(path, line_no, problem);
      fail(path, 0, "point " + std::to_string(i) + ": " + problem);
    };
    const Eigen::Vector3d p(v[l.x], v[l.y], v[l.z]);
    if (!p.allFinite()) {
      if (options.drop_nonfinite_points) continue;
      bad("non-finite position (set drop_nonfinite_points for organized clouds)");
    }
    cloud.positions.push_back(p);
    if (l.intensity >= 0) {
      if (!std::isfinite(v[l.intensity])) bad("non-finite intensity");
      cloud.intensity.push_back(static_cast<float>(v[l.intensity]));
    }
    if (l.nx >= 0) {
      const Eigen::Vector3f n(static_cast<float>(v[l.nx]), static_cast<float>(v[l.ny]),
                              static_cast<float>(v[l.nz]));
      if (!n.allFinite()) bad("non-finite normal");
      cloud.normals.push_back(n);
    }
    for (size_t e = 0; e < l.extra.size(); ++e) cloud.extra[e].values.push_back(v[l.extra[e]]);
  }
  return cloud;
}

void write_pcd(const std::filesystem::path& path, const PointCloud& cloud, const PcdWriteOptions& options) {
  cloud.check();
  const size_t n = cloud.size();
  std::string fields = "x y z", sizes, types, counts = "1 1 1";
  const char* psize = options.double_positions ? "8" : "4";
  sizes = std::string(psize) + " " + psize + " " + psize;
  types = "F F F";
  if (!cloud.intensity.empty()) fields += " intensity", sizes += " 4", types += " F", counts += " 1";
  if (!cloud.normals.empty())
    fields += " normal_x normal_y normal_z", sizes += " 4 4 4", types += " F F F", counts += " 1 1 1";
  for (const auto& f : cloud.extra) {
    if (f.name.empty() || f.name.find_first_of(" \t\n") != std::string::npos)
      throw std::invalid_argument("write_pcd: extra field name '" + f.name + "' is not one word");
    fields += " " + f.name, sizes += " 8", types += " F", counts += " 1";
  }
  write_file_atomic(path, [&](std::ostream& out) {
    out << "# .PCD v0.7 - Point Cloud Data file format (written by litgs)\nVERSION 0.7\nFIELDS " << fields
        << "\nSIZE " << sizes << "\nTYPE " << types << "\nCOUNT " << counts << "\nWIDTH " << n
        << "\nHEIGHT 1\nVIEWPOINT 0 0 0 1 0 0 0\nPOINTS " << n << "\nDATA binary\n";
    std::string buf;
    const auto put = [&buf](const auto value) {
      char b[sizeof(value)];
      std::memcpy(b, &value, sizeof(value));
      buf.append(b, sizeof(value));
    };
    for (size_t i = 0; i < n; ++i) {
      for (int k = 0; k < 3; ++k) {
        if (options.double_positions)
          put(cloud.positions[i][k]);
        else
          put(static_cast<float>(cloud.positions[i][k]));
      }
      if (!cloud.intensity.empty()) put(cloud.intensity[i]);
      if (!cloud.normals.empty())
        for (int k = 0; k < 3; ++k) put(cloud.normals[i][k]);
      for (const auto& f : cloud.extra) put(f.values[i]);
      if (buf.size() > (1u << 20))
        out.write(buf.data(), static_cast<std::streamsize>(buf.size())), buf.clear();
    }
    out.write(buf.data(), static_cast<std::streamsize>(buf.size()));
  });
}

}  // namespace litgs::io
