#include "io/colmap.h"

#include <bit>
#include <cmath>
#include <cstring>
#include <limits>
#include <set>
#include <stdexcept>

#include "io/atomic_file.h"
#include "io/error.h"
#include "io/file_bytes.h"
#include "io/text.h"

namespace litgs::io {
namespace fs = std::filesystem;

static_assert(std::endian::native == std::endian::little, "COLMAP binary I/O assumes a little-endian host");

namespace {

struct ModelInfo {
  ColmapCameraModel model;
  const char* name;
  int num_params;
};

constexpr ModelInfo kModels[] = {
    {ColmapCameraModel::kSimplePinhole, "SIMPLE_PINHOLE", 3},
    {ColmapCameraModel::kPinhole, "PINHOLE", 4},
    {ColmapCameraModel::kSimpleRadial, "SIMPLE_RADIAL", 4},
    {ColmapCameraModel::kRadial, "RADIAL", 5},
    {ColmapCameraModel::kOpenCv, "OPENCV", 8},
    {ColmapCameraModel::kOpenCvFisheye, "OPENCV_FISHEYE", 8},
    {ColmapCameraModel::kFullOpenCv, "FULL_OPENCV", 12},
    {ColmapCameraModel::kFov, "FOV", 5},
    {ColmapCameraModel::kSimpleRadialFisheye, "SIMPLE_RADIAL_FISHEYE", 4},
    {ColmapCameraModel::kRadialFisheye, "RADIAL_FISHEYE", 5},
    {ColmapCameraModel::kThinPrismFisheye, "THIN_PRISM_FISHEYE", 12},
};

const ModelInfo* info(ColmapCameraModel m) {
  for (const auto& i : kModels)
    if (i.model == m) return &i;
  return nullptr;
}

// A unit quaternion from COLMAP's (qw qx qy qz); the error message when it is not (near) unit.
std::string make_quaternion(const double q[4], Eigen::Quaterniond& out) {
  const Eigen::Quaterniond raw(q[0], q[1], q[2], q[3]);
  const double norm = raw.norm();
  if (!(std::abs(norm - 1.0) <= 1e-3)) return "quaternion norm is " + format_double(norm) + ", not 1";
  out = raw.normalized();
  return {};
}

// Where an entity was read: a text line or a binary byte offset, for errors found after parsing.
struct Where {
  fs::path file;
  int64_t line = 0;   // text: 1-based line
  uint64_t byte = 0;  // binary: offset
  bool binary = false;
  [[noreturn]] void fail_here(const std::string& problem) const {
    if (binary) fail_at_byte(file, byte, problem);
    fail(file, line, problem);
  }
};

// Cross-file checks shared by the text and binary readers.
void check_references(const ColmapModel& m, const std::vector<Where>& image_where,
                      const std::vector<Where>& point_where, bool has_points_file) {
  std::map<uint32_t, const ColmapImage*> images;
  for (size_t i = 0; i < m.images.size(); ++i) {
    const ColmapImage& im = m.images[i];
    if (!m.cameras.count(im.camera_id))
      image_where[i].fail_here("image " + std::to_string(im.id) + " ('" + im.name + "') references camera " +
                               std::to_string(im.camera_id) + ", which cameras does not define");
    if (!images.emplace(im.id, &im).second)
      image_where[i].fail_here("image id " + std::to_string(im.id) + " appears twice");
  }
  std::set<int64_t> point_ids;
  for (size_t i = 0; i < m.points.size(); ++i) {
    const ColmapPoint3D& p = m.points[i];
    if (!point_ids.insert(static_cast<int64_t>(p.id)).second)
      point_where[i].fail_here("point3D id " + std::to_string(p.id) + " appears twice");
    for (const auto& t : p.track) {
      const auto it = images.find(t.image_id);
      if (it == images.end())
        point_where[i].fail_here("point3D " + std::to_string(p.id) + " is seen by image " +
                                 std::to_string(t.image_id) + ", which images does not define");
      if (t.point2d_idx >= it->second->points2d.size())
        point_where[i].fail_here("point3D " + std::to_string(p.id) + " refers to point2D " +
                                 std::to_string(t.point2d_idx) + " of image " + std::to_string(t.image_id) +
                                 ", which has " + std::to_string(it->second->points2d.size()));
    }
  }
  if (!has_points_file) return;  // no points3D file: point ids cannot be checked
  for (size_t i = 0; i < m.images.size(); ++i)
    for (const auto& p2 : m.images[i].points2d)
      if (p2.point3d_id >= 0 && !point_ids.count(p2.point3d_id))
        image_where[i].fail_here("image " + std::to_string(m.images[i].id) + " references point3D " +
                                 std::to_string(p2.point3d_id) + ", which points3D does not define");
}

// ---- text ----

ColmapCamera parse_camera_line(const std::vector<std::string_view>& f, const fs::path& path, int64_t n) {
  if (f.size() < 4)
    fail(path, n,
         "expected 'CAMERA_ID MODEL WIDTH HEIGHT PARAMS[]', got " + std::to_string(f.size()) + " fields");
  ColmapCamera c;
  c.id =
      static_cast<uint32_t>(parse_int(f[0], path, n, "CAMERA_ID", 0, std::numeric_limits<uint32_t>::max()));
  if (!colmap_model_from_name(std::string(f[1]), c.model))
    fail(path, n, "unknown camera model '" + std::string(f[1]) + "'");
  c.width = static_cast<uint64_t>(parse_int(f[2], path, n, "WIDTH", 1, std::numeric_limits<int32_t>::max()));
  c.height =
      static_cast<uint64_t>(parse_int(f[3], path, n, "HEIGHT", 1, std::numeric_limits<int32_t>::max()));
  const int np = colmap_model_num_params(c.model);
  if (static_cast<int>(f.size()) - 4 != np)
    fail(path, n,
         std::string(f[1]) + " takes " + std::to_string(np) + " parameters, got " +
             std::to_string(f.size() - 4));
  for (size_t i = 4; i < f.size(); ++i) c.params.push_back(parse_double(f[i], path, n, "camera parameter"));
  return c;
}

}  // namespace

std::string colmap_model_name(ColmapCameraModel model) {
  const ModelInfo* i = info(model);
  return i ? i->name : "UNKNOWN(" + std::to_string(static_cast<int>(model)) + ")";
}

bool colmap_model_from_name(const std::string& name, ColmapCameraModel& model) {
  for (const auto& i : kModels)
    if (name == i.name) {
      model = i.model;
      return true;
    }
  return false;
}

bool colmap_model_from_id(int id, ColmapCameraModel& model) {
  for (const auto& i : kModels)
    if (static_cast<int>(i.model) == id) {
      model = i.model;
      return true;
    }
  return false;
}

int colmap_model_num_params(ColmapCameraModel model) {
  const ModelInfo* i = info(model);
  return i ? i->num_params : -1;
}

Eigen::Matrix4d ColmapImage::T_world_cam() const {
  Eigen::Matrix4d T = Eigen::Matrix4d::Identity();
  const Eigen::Matrix3d R_world_cam = q_cam_world.toRotationMatrix().transpose();
  T.topLeftCorner<3, 3>() = R_world_cam;
  T.topRightCorner<3, 1>() = -R_world_cam * t_cam_world;
  return T;
}

ColmapModel read_colmap_text(const fs::path& dir) {
  ColmapModel m;
  {
    const fs::path path = dir / "cameras.txt";
    LineReader reader(path);
    std::string line;
    while (reader.next(line)) {
      if (is_blank_or_comment(trim(line))) continue;
      const int64_t n = reader.line_number();
      ColmapCamera c = parse_camera_line(split_ws(line), path, n);
      const uint32_t id = c.id;
      if (!m.cameras.emplace(id, std::move(c)).second)
        fail(path, n, "camera id " + std::to_string(id) + " appears twice");
    }
  }
  std::vector<Where> image_where, point_where;
  {
    const fs::path path = dir / "images.txt";
    LineReader reader(path);
    std::string line;
    while (reader.next(line)) {
      if (is_blank_or_comment(trim(line))) continue;
      const int64_t n = reader.line_number();
      const auto f = split_ws(line);
      if (f.size() < 10)
        fail(path, n,
             "expected 'IMAGE_ID QW QX QY QZ TX TY TZ CAMERA_ID NAME', got " + std::to_string(f.size()) +
                 " fields");
      ColmapImage im;
      im.id = static_cast<uint32_t>(
          parse_int(f[0], path, n, "IMAGE_ID", 0, std::numeric_limits<uint32_t>::max()));
      double q[4];
      static const char* qn[4] = {"QW", "QX", "QY", "QZ"};
      for (int i = 0; i < 4; ++i) q[i] = parse_double(f[1 + i], path, n, qn[i]);
      if (const std::string e = make_quaternion(q, im.q_cam_world); !e.empty()) fail(path, n, e);
      im.t_cam_world = {parse_double(f[5], path, n, "TX"), parse_double(f[6], path, n, "TY"),
                        parse_double(f[7], path, n, "TZ")};
      im.camera_id = static_cast<uint32_t>(
          parse_int(f[8], path, n, "CAMERA_ID", 0, std::numeric_limits<uint32_t>::max()));
      // The name is the rest of the line (it may hold spaces).
      im.name =
          std::string(trim(std::string_view(line).substr(static_cast<size_t>(f[9].data() - line.data()))));
      image_where.push_back({path, n, 0, false});
      // The POINTS2D line follows unconditionally (possibly empty, possibly absent at the end of the file).
      std::string pts;
      if (reader.next(pts)) {
        const int64_t pn = reader.line_number();
        const auto p = split_ws(pts);
        if (p.size() % 3 != 0)
          fail(path, pn,
               "POINTS2D line of image " + std::to_string(im.id) + " has " + std::to_string(p.size()) +
                   " fields, not a multiple of 3 (X Y POINT3D_ID)");
        for (size_t i = 0; i < p.size(); i += 3) {
          ColmapPoint2D p2;
          p2.xy = {parse_double(p[i], path, pn, "X"), parse_double(p[i + 1], path, pn, "Y")};
          p2.point3d_id =
              parse_int(p[i + 2], path, pn, "POINT3D_ID", -1, std::numeric_limits<int64_t>::max());
          im.points2d.push_back(p2);
        }
      }
      m.images.push_back(std::move(im));
    }
  }
  const fs::path points_path = dir / "points3D.txt";
  if (fs::exists(points_path)) {
    LineReader reader(points_path);
    std::string line;
    while (reader.next(line)) {
      if (is_blank_or_comment(trim(line))) continue;
      const int64_t n = reader.line_number();
      const auto f = split_ws(line);
      if (f.size() < 8 || (f.size() - 8) % 2 != 0)
        fail(points_path, n,
             "expected 'POINT3D_ID X Y Z R G B ERROR' and (IMAGE_ID POINT2D_IDX) pairs, got " +
                 std::to_string(f.size()) + " fields");
      ColmapPoint3D p;
      p.id = static_cast<uint64_t>(
          parse_int(f[0], points_path, n, "POINT3D_ID", 0, std::numeric_limits<int64_t>::max()));
      p.xyz = {parse_double(f[1], points_path, n, "X"), parse_double(f[2], points_path, n, "Y"),
               parse_double(f[3], points_path, n, "Z")};
      for (int i = 0; i < 3; ++i)
        p.rgb[static_cast<size_t>(i)] =
            static_cast<uint8_t>(parse_int(f[4 + i], points_path, n, "RGB", 0, 255));
      p.error_px = parse_double(f[7], points_path, n, "ERROR");
      for (size_t i = 8; i < f.size(); i += 2)
        p.track.push_back({static_cast<uint32_t>(parse_int(f[i], points_path, n, "IMAGE_ID", 0,
                                                           std::numeric_limits<uint32_t>::max())),
                           static_cast<uint32_t>(parse_int(f[i + 1], points_path, n, "POINT2D_IDX", 0,
                                                           std::numeric_limits<uint32_t>::max()))});
      m.points.push_back(std::move(p));
      point_where.push_back({points_path, n, 0, false});
    }
  }
  check_references(m, image_where, point_where, fs::exists(points_path));
  return m;
}

// ---- binary ----

namespace {

class ByteReader {
 public:
  explicit ByteReader(fs::path path) : path_(std::move(path)), bytes_(read_file_bytes(path_)) {}

  template <class T>
  T read(const char* what) {
    need(sizeof(T), what);
    T v;
    std::memcpy(&v, bytes_.data() + pos_, sizeof(T));
    pos_ += sizeof(T);
    return v;
  }
  double read_double(const char* what) {
    const uint64_t at = pos_;
    const double v = read<double>(what);
    if (!std::isfinite(v)) fail_at_byte(path_, at, std::string(what) + " is not finite");
    return v;
  }
  std::string read_string(const char* what) {
    const size_t end = bytes_.find('\0', pos_);
    if (end == std::string::npos)
      fail_at_byte(path_, pos_, std::string("truncated: ") + what + " has no terminating NUL");
    std::string s = bytes_.substr(pos_, end - pos_);
    pos_ = end + 1;
    return s;
  }
  // A count of elements of at least min_bytes each: refuses counts the rest of the file cannot hold, so a
  // corrupt count never allocates gigabytes.
  uint64_t read_count(const char* what, uint64_t min_bytes) {
    const uint64_t at = pos_;
    const uint64_t n = read<uint64_t>(what);
    if (min_bytes > 0 && n > remaining() / min_bytes)
      fail_at_byte(path_, at,
                   std::string("truncated: ") + what + " is " + std::to_string(n) + " but only " +
                       std::to_string(remaining()) + " bytes follow");
    return n;
  }
  void expect_end() const {
    if (pos_ != bytes_.size())
      fail_at_byte(path_, pos_,
                   std::to_string(bytes_.size() - pos_) + " unexpected bytes after the last entry");
  }
  uint64_t pos() const { return pos_; }
  const fs::path& path() const { return path_; }

 private:
  uint64_t remaining() const { return bytes_.size() - pos_; }
  void need(size_t n, const char* what) const {
    if (remaining() < n)
      fail_at_byte(path_, pos_,
                   std::string("truncated: expected ") + std::to_string(n) + " bytes of " + what + ", " +
                       std::to_string(remaining()) + " left");
  }

  fs::path path_;
  std::string bytes_;
  uint64_t pos_ = 0;
};

class ByteWriter {
 public:
  template <class T>
  void put(T v) {
    char b[sizeof(T)];
    std::memcpy(b, &v, sizeof(T));
    bytes_.append(b, sizeof(T));
  }
  void put_string(const std::string& s) {
    if (s.find('\0') != std::string::npos) throw std::invalid_argument("COLMAP name holds a NUL: " + s);
    bytes_.append(s);
    bytes_.push_back('\0');
  }
  const std::string& bytes() const { return bytes_; }

 private:
  std::string bytes_;
};

void write_bytes(const fs::path& path, const std::string& bytes) {
  write_file_atomic(
      path, [&](std::ostream& out) { out.write(bytes.data(), static_cast<std::streamsize>(bytes.size())); });
}

}  // namespace

ColmapModel read_colmap_binary(const fs::path& dir) {
  ColmapModel m;
  {
    ByteReader r(dir / "cameras.bin");
    const uint64_t n = r.read_count("camera count", 4 + 4 + 8 + 8);
    for (uint64_t i = 0; i < n; ++i) {
      const uint64_t at = r.pos();
      ColmapCamera c;
      c.id = r.read<uint32_t>("camera_id");
      const uint64_t model_at = r.pos();
      const int32_t model_id = r.read<int32_t>("model_id");
      if (!colmap_model_from_id(model_id, c.model))
        fail_at_byte(r.path(), model_at, "unknown camera model id " + std::to_string(model_id));
      c.width = r.read<uint64_t>("width");
      c.height = r.read<uint64_t>("height");
      if (c.width == 0 || c.height == 0 || c.width > (1u << 30) || c.height > (1u << 30))
        fail_at_byte(r.path(), at,
                     "camera " + std::to_string(c.id) + " has an implausible size " +
                         std::to_string(c.width) + "x" + std::to_string(c.height));
      for (int k = 0; k < colmap_model_num_params(c.model); ++k)
        c.params.push_back(r.read_double("camera parameter"));
      const uint32_t id = c.id;
      if (!m.cameras.emplace(id, std::move(c)).second)
        fail_at_byte(r.path(), at, "camera id " + std::to_string(id) + " appears twice");
    }
    r.expect_end();
  }
  std::vector<Where> image_where, point_where;
  {
    ByteReader r(dir / "images.bin");
    const uint64_t n = r.read_count("image count", 4 + 7 * 8 + 4 + 1 + 8);
    for (uint64_t i = 0; i < n; ++i) {
      const uint64_t at = r.pos();
      ColmapImage im;
      im.id = r.read<uint32_t>("image_id");
      double q[4];
      for (double& v : q) v = r.read_double("qvec");
      if (const std::string e = make_quaternion(q, im.q_cam_world); !e.empty())
        fail_at_byte(r.path(), at, "image " + std::to_string(im.id) + ": " + e);
      for (int k = 0; k < 3; ++k) im.t_cam_world[k] = r.read_double("tvec");
      im.camera_id = r.read<uint32_t>("camera_id");
      im.name = r.read_string("name");
      const uint64_t np = r.read_count("points2D count", 8 + 8 + 8);
      im.points2d.resize(np);
      for (auto& p : im.points2d) {
        p.xy.x() = r.read_double("point2D x");
        p.xy.y() = r.read_double("point2D y");
        const uint64_t id = r.read<uint64_t>("point3D_id");
        p.point3d_id = id == std::numeric_limits<uint64_t>::max() ? -1 : static_cast<int64_t>(id);
      }
      m.images.push_back(std::move(im));
      image_where.push_back({r.path(), 0, at, true});
    }
    r.expect_end();
  }
  const fs::path points_path = dir / "points3D.bin";
  if (fs::exists(points_path)) {
    ByteReader r(points_path);
    const uint64_t n = r.read_count("point3D count", 8 + 3 * 8 + 3 + 8 + 8);
    for (uint64_t i = 0; i < n; ++i) {
      const uint64_t at = r.pos();
      ColmapPoint3D p;
      p.id = r.read<uint64_t>("point3D_id");
      for (int k = 0; k < 3; ++k) p.xyz[k] = r.read_double("xyz");
      for (auto& c : p.rgb) c = r.read<uint8_t>("rgb");
      p.error_px = r.read_double("error");
      const uint64_t nt = r.read_count("track length", 8);
      p.track.resize(nt);
      for (auto& t : p.track) {
        t.image_id = r.read<uint32_t>("track image_id");
        t.point2d_idx = r.read<uint32_t>("track point2D_idx");
      }
      m.points.push_back(std::move(p));
      point_where.push_back({points_path, 0, at, true});
    }
    r.expect_end();
  }
  check_references(m, image_where, point_where, fs::exists(points_path));
  return m;
}

ColmapModel read_colmap_model(const fs::path& dir) {
  if (!fs::is_directory(dir)) fail(dir, 0, "not a directory (expected a COLMAP model folder)");
  if (fs::exists(dir / "cameras.bin") && fs::exists(dir / "images.bin")) return read_colmap_binary(dir);
  if (fs::exists(dir / "cameras.txt") && fs::exists(dir / "images.txt")) return read_colmap_text(dir);
  fail(dir, 0, "no COLMAP model here (neither cameras.bin + images.bin nor cameras.txt + images.txt)");
}

void write_colmap_model(const fs::path& dir, const ColmapModel& m, bool binary) {
  for (const auto& [id, c] : m.cameras)
    if (static_cast<int>(c.params.size()) != colmap_model_num_params(c.model) || id != c.id)
      throw std::invalid_argument("camera " + std::to_string(id) + ": " + std::to_string(c.params.size()) +
                                  " parameters for " + colmap_model_name(c.model) + " (or id mismatch)");
  fs::create_directories(dir);
  const auto q_of = [](const ColmapImage& im) {
    return std::array<double, 4>{im.q_cam_world.w(), im.q_cam_world.x(), im.q_cam_world.y(),
                                 im.q_cam_world.z()};
  };
  if (binary) {
    ByteWriter cw;
    cw.put<uint64_t>(m.cameras.size());
    for (const auto& [id, c] : m.cameras) {
      cw.put<uint32_t>(c.id);
      cw.put<int32_t>(static_cast<int32_t>(c.model));
      cw.put<uint64_t>(c.width);
      cw.put<uint64_t>(c.height);
      for (double v : c.params) cw.put<double>(v);
    }
    write_bytes(dir / "cameras.bin", cw.bytes());
    ByteWriter iw;
    iw.put<uint64_t>(m.images.size());
    for (const auto& im : m.images) {
      iw.put<uint32_t>(im.id);
      for (double v : q_of(im)) iw.put<double>(v);
      for (int k = 0; k < 3; ++k) iw.put<double>(im.t_cam_world[k]);
      iw.put<uint32_t>(im.camera_id);
      iw.put_string(im.name);
      iw.put<uint64_t>(im.points2d.size());
      for (const auto& p : im.points2d) {
        iw.put<double>(p.xy.x());
        iw.put<double>(p.xy.y());
        iw.put<uint64_t>(p.point3d_id < 0 ? std::numeric_limits<uint64_t>::max()
                                          : static_cast<uint64_t>(p.point3d_id));
      }
    }
    write_bytes(dir / "images.bin", iw.bytes());
    ByteWriter pw;
    pw.put<uint64_t>(m.points.size());
    for (const auto& p : m.points) {
      pw.put<uint64_t>(p.id);
      for (int k = 0; k < 3; ++k) pw.put<double>(p.xyz[k]);
      for (uint8_t c : p.rgb) pw.put<uint8_t>(c);
      pw.put<double>(p.error_px);
      pw.put<uint64_t>(p.track.size());
      for (const auto& t : p.track) {
        pw.put<uint32_t>(t.image_id);
        pw.put<uint32_t>(t.point2d_idx);
      }
    }
    write_bytes(dir / "points3D.bin", pw.bytes());
    return;
  }
  const auto d = [](double x) { return format_double(x); };
  write_file_atomic(dir / "cameras.txt", [&](std::ostream& out) {
    out << "# Camera list with one line of data per camera:\n"
        << "#   CAMERA_ID, MODEL, WIDTH, HEIGHT, PARAMS[]\n"
        << "# Number of cameras: " << m.cameras.size() << "\n";
    for (const auto& [id, c] : m.cameras) {
      out << c.id << " " << colmap_model_name(c.model) << " " << c.width << " " << c.height;
      for (double v : c.params) out << " " << d(v);
      out << "\n";
    }
  });
  write_file_atomic(dir / "images.txt", [&](std::ostream& out) {
    out << "# Image list with two lines of data per image:\n"
        << "#   IMAGE_ID, QW, QX, QY, QZ, TX, TY, TZ, CAMERA_ID, NAME\n"
        << "#   POINTS2D[] as (X, Y, POINT3D_ID)\n"
        << "# Number of images: " << m.images.size() << "\n";
    for (const auto& im : m.images) {
      if (im.name.find('\n') != std::string::npos) throw std::invalid_argument("image name holds a newline");
      out << im.id;
      for (double v : q_of(im)) out << " " << d(v);
      for (int k = 0; k < 3; ++k) out << " " << d(im.t_cam_world[k]);
      out << " " << im.camera_id << " " << im.name << "\n";
      for (size_t i = 0; i < im.points2d.size(); ++i)
        out << (i ? " " : "") << d(im.points2d[i].xy.x()) << " " << d(im.points2d[i].xy.y()) << " "
            << im.points2d[i].point3d_id;
      out << "\n";
    }
  });
  write_file_atomic(dir / "points3D.txt", [&](std::ostream& out) {
    out << "# 3D point list with one line of data per point:\n"
        << "#   POINT3D_ID, X, Y, Z, R, G, B, ERROR, TRACK[] as (IMAGE_ID, POINT2D_IDX)\n"
        << "# Number of points: " << m.points.size() << "\n";
    for (const auto& p : m.points) {
      out << p.id << " " << d(p.xyz.x()) << " " << d(p.xyz.y()) << " " << d(p.xyz.z()) << " " << int(p.rgb[0])
          << " " << int(p.rgb[1]) << " " << int(p.rgb[2]) << " " << d(p.error_px);
      for (const auto& t : p.track) out << " " << t.image_id << " " << t.point2d_idx;
      out << "\n";
    }
  });
}

}  // namespace litgs::io
