// read_ros_bag: a reader of our own for ROS 1 bags (format 2.0, http://wiki.ros.org/Bags/Format/2.0) and of
// the four messages the engine imports, in plain C++ (no ROS headers, so not limited to C++17).
//
// Why not rosbag_storage: its reader trusts every length and offset in the file. Bag::readHeaderFromBuffer
// reads a record header and a data length wherever an index entry points, without comparing either to the
// chunk's size, and roscpp_serialization resizes a vector to the length a message claims before checking
// that the bytes are there. Measured on a writer-made bag (rosbag_storage 1.15.15, ASan): an index entry
// offset past its chunk is a SEGV in readHeaderFromBuffer; a PointCloud2 field count forged to 2^32 - 1 is a
// 206 GB allocation (std::bad_alloc without ASan); a data length forged to 2^32 - 16 allocates 4 GiB before
// the overrun is noticed. Here every length is checked against what contains it before anything is read or
// allocated; rosbag_storage is left to write bags for the tests (ros_bag.cc), which makes the tests a
// cross-check of two implementations.
//
// The bag is read through its index (like rosbag::View): the header record points at the connection and
// chunk-info records at the end of the file; each chunk is followed by one index-data record per connection
// with the (time, offset) of its messages. Messages of the wanted topics are delivered in time order (ties in
// file order), each decoded from its chunk (read from the file, or decompressed: bz2, lz4 frames).
#include <bzlib.h>
#include <lz4frame.h>

#include <algorithm>
#include <cmath>
#include <cstring>
#include <fstream>
#include <limits>
#include <map>
#include <memory>
#include <optional>
#include <string_view>
#include <tuple>

#include "io/error.h"
#include "io/ros_bag.h"

namespace litgs::io {
namespace fs = std::filesystem;

namespace {

constexpr std::string_view kMagic = "#ROSBAG V2.0\n";
constexpr uint8_t kOpMessageData = 0x02, kOpBagHeader = 0x03, kOpIndexData = 0x04, kOpChunk = 0x05,
                  kOpChunkInfo = 0x06, kOpConnection = 0x07;
// Record headers hold a few short fields (op, conn, topic, time, ...); a longer one is corrupt.
constexpr uint32_t kMaxRecordHeader = 1 << 20;
// A decompressed chunk: rosbag writes ~768 KiB chunks, or one message when a message is larger.
constexpr uint64_t kMaxChunkBytes = uint64_t{1} << 30;

// The message types the handlers take: ROS name and the MD5 of its definition (the layout decoded below).
struct MessageType {
  const char* name;
  const char* md5;
};
constexpr MessageType kImage = {"sensor_msgs/Image", "060021388200f6f0f447d0fcd9c64743"};
constexpr MessageType kPointCloud2 = {"sensor_msgs/PointCloud2", "1158d486dd51d683ce2f1be655c3c181"};
constexpr MessageType kImu = {"sensor_msgs/Imu", "6a62c6daae103f4ff57a132d6f95cec2"};
constexpr MessageType kOdometry = {"nav_msgs/Odometry", "cd5e73d190d741a2f92e81eda573aca7"};

// A problem with one message (its decoding or its type); read_ros_bag adds the bag's path.
struct MessageError : std::runtime_error {
  using std::runtime_error::runtime_error;
};

uint32_t le32(const uint8_t* p) {
  return static_cast<uint32_t>(p[0]) | static_cast<uint32_t>(p[1]) << 8 | static_cast<uint32_t>(p[2]) << 16 |
         static_cast<uint32_t>(p[3]) << 24;
}

// ROS time: seconds and nanoseconds, as ros::Time::toSec() converts them.
struct Stamp {
  uint32_t sec = 0, nsec = 0;
  bool zero() const { return sec == 0 && nsec == 0; }
  double seconds() const { return static_cast<double>(sec) + 1e-9 * static_cast<double>(nsec); }
  auto operator<=>(const Stamp&) const = default;
};

// ---------------------------------------------------------------------------------------------------------
// Records: <header_len u32><header: fields <len u32><name>=<value>><data_len u32><data>.

// Bytes of the file or of a decompressed chunk, read with bounds checks; `where(pos)` names a position in
// errors ("byte N", or "byte N of the chunk at byte M").
class Bytes {
 public:
  virtual ~Bytes() = default;
  virtual uint64_t size() const = 0;
  virtual void read(uint64_t pos, void* dst, size_t n) = 0;  // within size(), checked by the caller
  virtual std::string where(uint64_t pos) const = 0;
  virtual const fs::path& path() const = 0;

  [[noreturn]] void fail(uint64_t pos, const std::string& problem) const {
    io::fail(path(), 0, where(pos) + ": " + problem);
  }
  // Reads n bytes at pos, which must lie within [pos, end) (end <= size()).
  void read_within(uint64_t pos, uint64_t end, void* dst, size_t n, const char* what) {
    if (pos > end || n > end - pos)
      fail(pos, std::string("bag ends (or its enclosing record ends) inside the ") + what + " (" +
                    std::to_string(n) + " bytes wanted, " + std::to_string(pos > end ? 0 : end - pos) +
                    " left)");
    read(pos, dst, n);
  }
  uint32_t u32_within(uint64_t pos, uint64_t end, const char* what) {
    uint8_t b[4];
    read_within(pos, end, b, 4, what);
    return le32(b);
  }
};

class FileBytes final : public Bytes {
 public:
  explicit FileBytes(const fs::path& path) : path_(path), in_(path, std::ios::binary) {
    std::error_code ec;
    size_ = fs::file_size(path, ec);
    if (!in_ || ec) io::fail(path, 0, "cannot open the bag");
  }
  uint64_t size() const override { return size_; }
  void read(uint64_t pos, void* dst, size_t n) override {
    in_.seekg(static_cast<std::streamoff>(pos));
    in_.read(static_cast<char*>(dst), static_cast<std::streamsize>(n));
    if (!in_ || static_cast<size_t>(in_.gcount()) != n) io::fail(path_, 0, where(pos) + ": read error");
  }
  std::string where(uint64_t pos) const override { return "byte " + std::to_string(pos); }
  const fs::path& path() const override { return path_; }

 private:
  fs::path path_;
  std::ifstream in_;
  uint64_t size_ = 0;
};

class ChunkBytes final : public Bytes {
 public:
  ChunkBytes(const fs::path& path, uint64_t chunk_pos, std::vector<uint8_t> data)
      : path_(path), chunk_pos_(chunk_pos), data_(std::move(data)) {}
  uint64_t size() const override { return data_.size(); }
  void read(uint64_t pos, void* dst, size_t n) override { std::memcpy(dst, data_.data() + pos, n); }
  std::string where(uint64_t pos) const override {
    return "byte " + std::to_string(pos) + " of the chunk at byte " + std::to_string(chunk_pos_);
  }
  const fs::path& path() const override { return path_; }

 private:
  fs::path path_;
  uint64_t chunk_pos_;
  std::vector<uint8_t> data_;
};

// Bytes of an uncompressed chunk, read in place from the file: errors say which chunk.
class InFileChunk final : public Bytes {
 public:
  InFileChunk(Bytes& file, uint64_t chunk_pos) : file_(file), chunk_pos_(chunk_pos) {}
  uint64_t size() const override { return file_.size(); }
  void read(uint64_t pos, void* dst, size_t n) override { file_.read(pos, dst, n); }
  std::string where(uint64_t pos) const override {
    return file_.where(pos) + " (in the chunk at byte " + std::to_string(chunk_pos_) + ")";
  }
  const fs::path& path() const override { return file_.path(); }

 private:
  Bytes& file_;
  uint64_t chunk_pos_;
};

struct Record {
  uint64_t pos = 0;  // of the header length
  uint8_t op = 0;
  std::map<std::string, std::string, std::less<>> fields;  // name -> raw value bytes
  uint64_t data_pos = 0;
  uint32_t data_len = 0;
  uint64_t end() const { return data_pos + data_len; }
};

// Parses header fields from `h` (the record at `pos` of `src`, for errors).
std::map<std::string, std::string, std::less<>> parse_fields(Bytes& src, uint64_t pos, std::string_view h) {
  std::map<std::string, std::string, std::less<>> fields;
  size_t at = 0;
  while (at < h.size()) {
    if (h.size() - at < 4) src.fail(pos, "record header ends inside a field length");
    const uint32_t len = le32(reinterpret_cast<const uint8_t*>(h.data() + at));
    at += 4;
    if (len > h.size() - at)
      src.fail(pos, "record header field of " + std::to_string(len) + " bytes overruns the header");
    const std::string_view field = h.substr(at, len);
    at += len;
    const size_t eq = field.find('=');
    if (eq == std::string_view::npos) src.fail(pos, "record header field without '='");
    fields.emplace(std::string(field.substr(0, eq)), std::string(field.substr(eq + 1)));
  }
  return fields;
}

// The record at `pos`, which must end by `end`; its data is left in place.
Record read_record(Bytes& src, uint64_t pos, uint64_t end) {
  Record r;
  r.pos = pos;
  const uint32_t header_len = src.u32_within(pos, end, "record header length");
  if (header_len > kMaxRecordHeader)
    src.fail(pos, "record header of " + std::to_string(header_len) + " bytes (corrupt: headers are short)");
  std::string header(header_len, '\0');
  src.read_within(pos + 4, end, header.data(), header_len, "record header");
  r.fields = parse_fields(src, pos, header);
  r.data_len = src.u32_within(pos + 4 + header_len, end, "record data length");
  r.data_pos = pos + 8 + header_len;
  if (r.data_len > end - r.data_pos)
    src.fail(pos, "record data of " + std::to_string(r.data_len) + " bytes runs past the end (" +
                      std::to_string(end - r.data_pos) + " left)");
  const auto op = r.fields.find("op");
  if (op == r.fields.end() || op->second.size() != 1) src.fail(pos, "record without a one-byte 'op' field");
  r.op = static_cast<uint8_t>(op->second[0]);
  return r;
}

void expect_op(Bytes& src, const Record& r, uint8_t op, const char* what) {
  if (r.op != op)
    src.fail(r.pos, std::string("expected a ") + what + " record (op " + std::to_string(op) + "), found op " +
                        std::to_string(r.op));
}

const std::string& field(Bytes& src, const Record& r, std::string_view name) {
  const auto it = r.fields.find(name);
  if (it == r.fields.end())
    src.fail(r.pos, "record (op " + std::to_string(r.op) + ") has no '" + std::string(name) + "' field");
  return it->second;
}

template <class T>
T field_int(Bytes& src, const Record& r, std::string_view name) {
  const std::string& v = field(src, r, name);
  if (v.size() != sizeof(T))
    src.fail(r.pos, "field '" + std::string(name) + "' has " + std::to_string(v.size()) +
                        " bytes, expected " + std::to_string(sizeof(T)));
  T x = 0;
  for (size_t i = 0; i < sizeof(T); ++i) x |= static_cast<T>(static_cast<uint8_t>(v[i])) << (8 * i);
  return x;
}

// ---------------------------------------------------------------------------------------------------------
// Chunks.

struct Chunk {
  uint64_t pos = 0;  // of the chunk record
  std::string compression;
  uint32_t size = 0;  // uncompressed
  uint64_t data_pos = 0;
  uint32_t data_len = 0;
};

// Grows `out` towards `limit` bytes, as decompression needs (so a forged size allocates nothing up front).
void grow(std::vector<uint8_t>& out, uint64_t limit) {
  out.resize(static_cast<size_t>(std::min<uint64_t>(limit, std::max<uint64_t>(out.size() * 2, 1 << 16))));
}

std::vector<uint8_t> decompress_bz2(Bytes& src, const Chunk& c, const std::vector<uint8_t>& in) {
  bz_stream s{};
  if (BZ2_bzDecompressInit(&s, 0, 0) != BZ_OK) src.fail(c.pos, "bz2: cannot initialise the decompressor");
  const std::unique_ptr<bz_stream, int (*)(bz_stream*)> end(&s, BZ2_bzDecompressEnd);
  std::vector<uint8_t> out;
  const uint64_t limit = uint64_t{c.size} + 1;  // one more than declared, to see an overlong stream
  s.next_in = const_cast<char*>(reinterpret_cast<const char*>(in.data()));
  s.avail_in = static_cast<unsigned>(in.size());
  size_t produced = 0;
  for (;;) {
    if (produced == out.size()) {
      if (out.size() == limit) break;
      grow(out, limit);
    }
    s.next_out = reinterpret_cast<char*>(out.data() + produced);
    s.avail_out = static_cast<unsigned>(out.size() - produced);
    const int rc = BZ2_bzDecompress(&s);
    produced = out.size() - s.avail_out;
    if (rc == BZ_STREAM_END) break;
    if (rc != BZ_OK) src.fail(c.pos, "bz2 chunk is corrupt (libbz2 error " + std::to_string(rc) + ")");
    if (s.avail_in == 0 && s.avail_out > 0) src.fail(c.pos, "bz2 chunk is truncated");
  }
  if (produced != c.size)
    src.fail(c.pos, "bz2 chunk decompresses to " + std::string(produced == limit ? "more than " : "") +
                        std::to_string(std::min<uint64_t>(produced, c.size)) + " bytes, its header says " +
                        std::to_string(c.size));
  out.resize(c.size);  // == produced
  return out;
}

// rosbag's "lz4" chunks are LZ4 frames (roslz4 writes the frame format).
std::vector<uint8_t> decompress_lz4(Bytes& src, const Chunk& c, const std::vector<uint8_t>& in) {
  LZ4F_dctx* raw = nullptr;
  if (LZ4F_isError(LZ4F_createDecompressionContext(&raw, LZ4F_VERSION)))
    src.fail(c.pos, "lz4: cannot initialise the decompressor");
  const std::unique_ptr<LZ4F_dctx, size_t (*)(LZ4F_dctx*)> ctx(raw, LZ4F_freeDecompressionContext);
  std::vector<uint8_t> out;
  const uint64_t limit = uint64_t{c.size} + 1;
  size_t consumed = 0, produced = 0;
  for (;;) {
    if (produced == out.size()) {
      if (out.size() == limit) break;
      grow(out, limit);
    }
    size_t dst = out.size() - produced, srcn = in.size() - consumed;
    const size_t rc =
        LZ4F_decompress(ctx.get(), out.data() + produced, &dst, in.data() + consumed, &srcn, nullptr);
    if (LZ4F_isError(rc)) src.fail(c.pos, std::string("lz4 chunk is corrupt: ") + LZ4F_getErrorName(rc));
    consumed += srcn;
    produced += dst;
    if (rc == 0) break;  // the frame is complete
    // With input left and room for output, LZ4F always makes progress: none means the input is used up.
    if (srcn == 0 && dst == 0) src.fail(c.pos, "lz4 chunk is truncated");
  }
  if (produced != c.size)
    src.fail(c.pos, "lz4 chunk decompresses to " + std::string(produced == limit ? "more than " : "") +
                        std::to_string(std::min<uint64_t>(produced, c.size)) + " bytes, its header says " +
                        std::to_string(c.size));
  if (consumed != in.size()) src.fail(c.pos, "lz4 chunk has bytes after its frame");
  out.resize(c.size);  // == produced
  return out;
}

std::vector<uint8_t> decompress(Bytes& file, const Chunk& c) {
  std::vector<uint8_t> in(c.data_len);
  file.read_within(c.data_pos, c.data_pos + c.data_len, in.data(), in.size(), "chunk data");
  if (c.compression == "bz2") return decompress_bz2(file, c, in);
  if (c.compression == "lz4") return decompress_lz4(file, c, in);
  file.fail(c.pos, "chunk compression '" + c.compression + "' is not none, bz2 or lz4");
}

// ---------------------------------------------------------------------------------------------------------
// Messages: the ROS 1 serialization (little-endian; strings and variable arrays as uint32 length + bytes;
// fixed arrays without length).

class Wire {
 public:
  Wire(const std::vector<uint8_t>& b, const std::string& where) : b_(b), where_(where) {}
  const uint8_t* take(size_t n, const char* what) {
    if (n > b_.size() - at_)
      throw MessageError(where_ + ": message of " + std::to_string(b_.size()) + " bytes ends inside " + what +
                         " (" + std::to_string(n) + " bytes at byte " + std::to_string(at_) + ")");
    const uint8_t* p = b_.data() + at_;
    at_ += n;
    return p;
  }
  uint8_t u8(const char* what) { return *take(1, what); }
  uint32_t u32(const char* what) { return le32(take(4, what)); }
  double f64(const char* what) {
    double v;
    std::memcpy(&v, take(8, what), 8);
    return v;
  }
  std::string str(const char* what) {
    const uint32_t n = u32(what);
    const uint8_t* p = take(n, what);
    return std::string(reinterpret_cast<const char*>(p), n);
  }
  // A uint8[] of the declared length: a pointer into the message (never a copy of a claimed size).
  std::pair<const uint8_t*, uint32_t> bytes(const char* what) {
    const uint32_t n = u32(what);
    return {take(n, what), n};
  }
  Stamp header() {  // std_msgs/Header: seq, stamp, frame_id
    take(4, "header.seq");
    Stamp s;
    s.sec = u32("header.stamp");
    s.nsec = u32("header.stamp");
    str("header.frame_id");
    return s;
  }
  void finish() const {
    if (at_ != b_.size())
      throw MessageError(where_ + ": " + std::to_string(b_.size() - at_) +
                         " bytes after the end of the message (not the layout its type names)");
  }
  const std::string& where() const { return where_; }

 private:
  const std::vector<uint8_t>& b_;
  const std::string& where_;
  size_t at_ = 0;
};

// sensor_msgs/Image encodings -> channels, bytes per channel.
bool encoding_layout(const std::string& e, int& channels, int& bytes) {
  struct L {
    const char* name;
    int channels, bytes;
  };
  static const L layouts[] = {{"mono8", 1, 1}, {"8UC1", 1, 1},   {"mono16", 1, 2}, {"16UC1", 1, 2},
                              {"rgb8", 3, 1},  {"bgr8", 3, 1},   {"8UC3", 3, 1},   {"rgba8", 4, 1},
                              {"bgra8", 4, 1}, {"8UC4", 4, 1},   {"rgb16", 3, 2},  {"bgr16", 3, 2},
                              {"16UC3", 3, 2}, {"rgba16", 4, 2}, {"bgra16", 4, 2}, {"16UC4", 4, 2}};
  for (const auto& l : layouts)
    if (e == l.name) {
      channels = l.channels;
      bytes = l.bytes;
      return true;
    }
  return false;
}

// sensor_msgs/Image: header, height, width, encoding, is_bigendian, step, data.
Image decode_image(Wire& w, Stamp& stamp) {
  stamp = w.header();
  const uint32_t height = w.u32("height"), width = w.u32("width");
  const std::string encoding = w.str("encoding");
  const bool big = w.u8("is_bigendian") != 0;
  const uint32_t step = w.u32("step");
  const auto [data, size] = w.bytes("data");
  w.finish();
  int channels = 0, bytes = 0;
  if (!encoding_layout(encoding, channels, bytes))
    throw MessageError(w.where() + ": image encoding '" + encoding + "' is not supported");
  // 64-bit products of 32-bit fields: no wrap.
  const uint64_t row = uint64_t{width} * static_cast<uint64_t>(channels * bytes);
  if (width == 0 || height == 0 || width > std::numeric_limits<int>::max() ||
      height > std::numeric_limits<int>::max() || step < row || size < uint64_t{step} * height)
    throw MessageError(w.where() + ": image " + std::to_string(width) + "x" + std::to_string(height) +
                       " step " + std::to_string(step) + " with " + std::to_string(size) +
                       " bytes is inconsistent");
  Image im;
  im.width = static_cast<int>(width);
  im.height = static_cast<int>(height);
  im.channels = channels;
  im.bit_depth = 8 * bytes;
  const size_t values = static_cast<size_t>(width) * static_cast<size_t>(channels);
  im.data.resize(values * height);
  for (uint32_t y = 0; y < height; ++y) {
    const uint8_t* src = data + static_cast<size_t>(y) * step;
    uint16_t* dst = im.data.data() + static_cast<size_t>(y) * values;
    for (size_t i = 0; i < values; ++i) {
      if (bytes == 1) {
        dst[i] = src[i];
      } else {
        const uint16_t b0 = src[2 * i], b1 = src[2 * i + 1];
        dst[i] = big ? static_cast<uint16_t>((b0 << 8) | b1) : static_cast<uint16_t>((b1 << 8) | b0);
      }
    }
  }
  return im;
}

// sensor_msgs/PointField datatypes.
enum : uint8_t { kInt8 = 1, kUint8, kInt16, kUint16, kInt32, kUint32, kFloat32, kFloat64 };

int field_size(uint8_t datatype) {
  switch (datatype) {
    case kInt8:
    case kUint8:
      return 1;
    case kInt16:
    case kUint16:
      return 2;
    case kInt32:
    case kUint32:
    case kFloat32:
      return 4;
    case kFloat64:
      return 8;
    default:
      return 0;
  }
}

double read_field(const uint8_t* p, uint8_t datatype) {
  const auto get = [p](auto v) {
    std::memcpy(&v, p, sizeof v);
    return static_cast<double>(v);
  };
  switch (datatype) {
    case kInt8:
      return get(int8_t{});
    case kUint8:
      return get(uint8_t{});
    case kInt16:
      return get(int16_t{});
    case kUint16:
      return get(uint16_t{});
    case kInt32:
      return get(int32_t{});
    case kUint32:
      return get(uint32_t{});
    case kFloat32:
      return get(float{});
    default:
      return get(double{});
  }
}

// sensor_msgs/PointCloud2: header, height, width, fields[] {name, offset, datatype, count}, is_bigendian,
// point_step, row_step, data, is_dense. x y z (float32/float64), an optional intensity (any type) and an
// optional per-point time, kept as the extra field "time" in seconds after the stamp: Velodyne's "time"
// (float seconds) or Ouster's "t" (integer nanoseconds).
PointCloud decode_point_cloud2(Wire& w, Stamp& stamp) {
  stamp = w.header();
  const uint32_t height = w.u32("height"), width = w.u32("width");
  struct Field {
    std::string name;
    uint32_t offset = 0;
    uint8_t datatype = 0;
  };
  std::vector<Field> fields;
  const uint32_t n_fields = w.u32("fields");
  for (uint32_t i = 0; i < n_fields; ++i) {  // each field takes >= 13 bytes: the loop ends at the data's end
    Field f;
    f.name = w.str("fields[].name");
    f.offset = w.u32("fields[].offset");
    f.datatype = w.u8("fields[].datatype");
    w.u32("fields[].count");
    fields.push_back(std::move(f));
  }
  const bool big = w.u8("is_bigendian") != 0;
  const uint32_t point_step = w.u32("point_step"), row_step = w.u32("row_step");
  const auto [data, size] = w.bytes("data");
  w.u8("is_dense");
  w.finish();
  if (big) throw MessageError(w.where() + ": big-endian point clouds are not supported");

  const Field* f[6] = {nullptr, nullptr, nullptr, nullptr, nullptr, nullptr};
  static const char* names[6] = {"x", "y", "z", "intensity", "time", "t"};
  for (const auto& field : fields)
    for (int k = 0; k < 6; ++k)
      if (field.name == names[k]) f[k] = &field;
  for (int k = 0; k < 6; ++k) {
    if (!f[k]) {
      if (k < 3) throw MessageError(w.where() + ": point cloud has no field '" + names[k] + "'");
      continue;
    }
    const int bytes = field_size(f[k]->datatype);
    if (bytes == 0 || (k < 3 && f[k]->datatype != kFloat32 && f[k]->datatype != kFloat64))
      throw MessageError(w.where() + ": field '" + names[k] + "' has datatype " +
                         std::to_string(f[k]->datatype) + " (x y z must be float32 or float64)");
    // Subtraction, not offset + size: both are 32-bit, and a forged offset near 2^32 would wrap the sum
    // below point_step (the issue-12 finding).
    if (f[k]->offset > point_step || static_cast<uint32_t>(bytes) > point_step - f[k]->offset)
      throw MessageError(w.where() + ": field '" + names[k] + "' (offset " + std::to_string(f[k]->offset) +
                         ", " + std::to_string(bytes) + " bytes) lies beyond point_step " +
                         std::to_string(point_step));
  }
  // 64-bit products of 32-bit fields: no wrap. Every point then lies inside the data: row r starts at
  // r * row_step <= (height - 1) * row_step and its width points take width * point_step <= row_step.
  if (uint64_t{row_step} < uint64_t{width} * point_step || uint64_t{size} < uint64_t{row_step} * height)
    throw MessageError(w.where() + ": point cloud data (" + std::to_string(size) +
                       " bytes) is shorter than height * row_step, or row_step < width * point_step");
  PointCloud c;
  // point_step >= 4 (x is inside it), so width * height <= size / 4: bounded by the message.
  c.positions.reserve(static_cast<size_t>(width) * height);
  const Field* time = f[4] ? f[4] : f[5];
  const double time_scale = f[4] ? 1.0 : 1e-9;  // "t" counts nanoseconds
  if (time) c.extra.push_back({"time", {}});
  for (uint32_t r = 0; r < height; ++r)
    for (uint32_t i = 0; i < width; ++i) {
      const uint8_t* p = data + static_cast<size_t>(r) * row_step + static_cast<size_t>(i) * point_step;
      const Eigen::Vector3d x(read_field(p + f[0]->offset, f[0]->datatype),
                              read_field(p + f[1]->offset, f[1]->datatype),
                              read_field(p + f[2]->offset, f[2]->datatype));
      if (!x.allFinite()) continue;
      c.positions.push_back(x);
      if (f[3]) c.intensity.push_back(static_cast<float>(read_field(p + f[3]->offset, f[3]->datatype)));
      if (time) {
        const double dt = read_field(p + time->offset, time->datatype) * time_scale;
        if (!std::isfinite(dt)) throw MessageError(w.where() + ": a point's time is not finite");
        c.extra[0].values.push_back(dt);
      }
    }
  return c;
}

Eigen::Vector3d vec3(Wire& w, const char* what) {
  const double x = w.f64(what), y = w.f64(what), z = w.f64(what);
  return {x, y, z};
}

void finite(const Wire& w, const Eigen::Vector3d& v, const char* what) {
  if (!v.allFinite()) throw MessageError(w.where() + ": " + what + " is not finite");
}

// sensor_msgs/Imu: header, orientation (x y z w), its covariance[9], angular_velocity, covariance[9],
// linear_acceleration, covariance[9].
ImuSample decode_imu(Wire& w, Stamp& stamp) {
  stamp = w.header();
  w.take(8 * (4 + 9), "orientation");
  ImuSample s;
  s.gyro_rad_s = vec3(w, "angular_velocity");
  w.take(8 * 9, "angular_velocity_covariance");
  s.accel_m_s2 = vec3(w, "linear_acceleration");
  w.take(8 * 9, "linear_acceleration_covariance");
  w.finish();
  finite(w, s.gyro_rad_s, "angular_velocity");
  finite(w, s.accel_m_s2, "linear_acceleration");
  return s;
}

// nav_msgs/Odometry: header, child_frame_id, pose {position, orientation (x y z w), covariance[36]},
// twist {linear, angular, covariance[36]}.
TumPose decode_odometry(Wire& w, Stamp& stamp) {
  stamp = w.header();
  w.str("child_frame_id");
  TumPose p;
  p.p_world = vec3(w, "pose.position");
  const double qx = w.f64("pose.orientation"), qy = w.f64("pose.orientation"), qz = w.f64("pose.orientation"),
               qw = w.f64("pose.orientation");
  w.take(8 * 36, "pose.covariance");
  w.take(8 * (6 + 36), "twist");
  w.finish();
  finite(w, p.p_world, "pose.position");
  const Eigen::Quaterniond q(qw, qx, qy, qz);
  if (!(std::abs(q.norm() - 1) < 1e-3))
    throw MessageError(w.where() + ": orientation is not a unit quaternion");
  p.q_world_body = q.normalized();
  return p;
}

// ---------------------------------------------------------------------------------------------------------

struct Connection {
  std::string topic, type, md5;
};

struct Entry {
  Stamp time;  // the receive time of the index (rosbag::MessageInstance::getTime)
  uint32_t chunk = 0, offset = 0, conn = 0;
};

class BagReader {
 public:
  explicit BagReader(const fs::path& path) : file_(path) {}

  // Reads the header record, the connections and chunk infos at the index position, and each chunk's
  // index-data records; keeps the entries whose connection `wanted` accepts.
  template <class Wanted>
  void index(Wanted&& wanted) {
    const Record header = read_header();
    const uint64_t index_pos = field_int<uint64_t>(file_, header, "index_pos");
    const uint32_t conn_count = field_int<uint32_t>(file_, header, "conn_count");
    const uint32_t chunk_count = field_int<uint32_t>(file_, header, "chunk_count");
    if (index_pos == 0)
      file_.fail(
          header.pos,
          "bag is not indexed (the recording did not finish; `import bag --reindex` reads its complete "
          "chunks, as `rosbag reindex` would)");
    if (index_pos < header.end() || index_pos > file_.size())
      file_.fail(header.pos, "index position " + std::to_string(index_pos) +
                                 " lies outside the chunks' end (" + std::to_string(header.end()) + ".." +
                                 std::to_string(file_.size()) +
                                 "; a bag cut short: `import bag --reindex` reads its complete chunks)");

    // Connection records, then chunk-info records (each read consumes >= 8 bytes: forged counts end at EOF).
    uint64_t pos = index_pos;
    for (uint32_t i = 0; i < conn_count; ++i) {
      const Record r = read_record(file_, pos, file_.size());
      expect_op(file_, r, kOpConnection, "connection");
      auto [id, c] = parse_connection(file_, r);
      if (!connections_.emplace(id, std::move(c)).second)
        file_.fail(r.pos, "connection " + std::to_string(id) + " is defined twice");
      pos = r.end();
    }
    std::vector<std::pair<uint64_t, uint32_t>> chunk_infos;  // chunk position, its number of connections
    for (uint32_t i = 0; i < chunk_count; ++i) {
      const Record r = read_record(file_, pos, file_.size());
      expect_op(file_, r, kOpChunkInfo, "chunk info");
      if (field_int<uint32_t>(file_, r, "ver") != 1) file_.fail(r.pos, "chunk info version is not 1");
      const uint32_t count = field_int<uint32_t>(file_, r, "count");
      if (uint64_t{count} * 8 != r.data_len)
        file_.fail(r.pos, "chunk info lists " + std::to_string(count) + " connections in " +
                              std::to_string(r.data_len) + " bytes (8 each)");
      chunk_infos.emplace_back(field_int<uint64_t>(file_, r, "chunk_pos"), count);
      pos = r.end();
    }

    // Each chunk and the index-data records after it.
    for (const auto& [chunk_pos, n_conn] : chunk_infos) {
      if (chunk_pos < header.end() || chunk_pos >= index_pos)
        file_.fail(pos, "chunk position " + std::to_string(chunk_pos) + " lies outside the chunks (" +
                            std::to_string(header.end()) + ".." + std::to_string(index_pos) + ")");
      const Record r = read_record(file_, chunk_pos, index_pos);
      expect_op(file_, r, kOpChunk, "chunk");
      const Chunk c = checked_chunk(r);
      const auto chunk = static_cast<uint32_t>(chunks_.size());
      chunks_.push_back(c);
      uint64_t at = r.end();
      for (uint32_t k = 0; k < n_conn; ++k) {
        const Record ix = read_record(file_, at, index_pos);
        expect_op(file_, ix, kOpIndexData, "index data");
        if (field_int<uint32_t>(file_, ix, "ver") != 1) file_.fail(ix.pos, "index data version is not 1");
        const uint32_t conn = field_int<uint32_t>(file_, ix, "conn");
        const uint32_t count = field_int<uint32_t>(file_, ix, "count");
        if (uint64_t{count} * 12 != ix.data_len)
          file_.fail(ix.pos, "index data lists " + std::to_string(count) + " messages in " +
                                 std::to_string(ix.data_len) + " bytes (12 each)");
        const auto it = connections_.find(conn);
        if (it == connections_.end())
          file_.fail(ix.pos,
                     "index data of connection " + std::to_string(conn) + ", which the bag does not define");
        if (wanted(it->second)) {
          std::vector<uint8_t> b(ix.data_len);
          file_.read_within(ix.data_pos, ix.end(), b.data(), b.size(), "index data");
          for (uint32_t m = 0; m < count; ++m) {
            const uint8_t* e = b.data() + 12 * static_cast<size_t>(m);
            const uint32_t offset = le32(e + 8);
            if (offset >= c.size)
              file_.fail(ix.pos, "index entry " + std::to_string(m) + " points at byte " +
                                     std::to_string(offset) + " of a chunk of " + std::to_string(c.size) +
                                     " bytes");
            entries_.push_back({{le32(e), le32(e + 4)}, chunk, offset, conn});
          }
        }
        at = ix.end();
      }
    }
    std::sort(entries_.begin(), entries_.end(), [](const Entry& a, const Entry& b) {
      return std::tie(a.time, a.chunk, a.offset) < std::tie(b.time, b.chunk, b.offset);
    });
  }

  // Without the index (`reindex`, for a recording cut short, as `rosbag reindex` does): the records are read
  // in file order from the bag header on, connections from their records (inside chunks and after them),
  // messages from each complete chunk's message-data records. Reading stops at the first record that does
  // not fit in the file or does not parse (the chunk being written when the recorder stopped); what was
  // left unread is reported. Each chunk is checked as index() checks it.
  template <class Wanted>
  RosBagRecovery scan(Wanted&& wanted) {
    const Record header = read_header();
    RosBagRecovery report;
    report.used = true;
    std::vector<Entry> found;
    uint64_t pos = header.end();
    while (pos < file_.size()) {
      try {
        const Record r = read_record(file_, pos, file_.size());
        if (r.op == kOpConnection) {
          add_scanned_connection(file_, r);
        } else if (r.op == kOpChunk) {
          scan_chunk(r, found);
          ++report.chunks;
        }
        pos = r.end();
      } catch (const IoError& error) {
        report.unread_bytes = file_.size() - pos;
        report.stopped_at = error.what();
        break;
      }
    }
    for (const Entry& e : found) {
      const auto it = connections_.find(e.conn);
      if (it != connections_.end() && wanted(it->second)) entries_.push_back(e);
    }
    std::sort(entries_.begin(), entries_.end(), [](const Entry& a, const Entry& b) {
      return std::tie(a.time, a.chunk, a.offset) < std::tie(b.time, b.chunk, b.offset);
    });
    return report;
  }

  const std::vector<Entry>& entries() const { return entries_; }
  const Connection& connection(uint32_t id) const { return connections_.at(id); }

  // The serialized message of `e` (its message-data record in the chunk).
  std::vector<uint8_t> message(const Entry& e) {
    const Chunk& c = chunks_[e.chunk];
    InFileChunk in_file(file_, c.pos);
    Bytes* src = &in_file;
    uint64_t begin = c.data_pos, end = c.data_pos + c.data_len;
    if (c.compression != "none") {
      if (cached_chunk_ != e.chunk) {
        cached_.emplace(file_.path(), c.pos, decompress(file_, c));
        cached_chunk_ = e.chunk;
      }
      src = &*cached_;
      begin = 0;
      end = cached_->size();
    }
    const Record r = read_record(*src, begin + e.offset, end);
    expect_op(*src, r, kOpMessageData, "message data");
    if (field_int<uint32_t>(*src, r, "conn") != e.conn)
      src->fail(r.pos, "message record's connection differs from its index entry's (" +
                           std::to_string(e.conn) + ")");
    std::vector<uint8_t> bytes(r.data_len);
    src->read_within(r.data_pos, r.end(), bytes.data(), bytes.size(), "message data");
    return bytes;
  }

  const fs::path& path() const { return file_.path(); }

 private:
  // The version line and the bag header record.
  Record read_header() {
    char magic[kMagic.size()] = {};
    if (file_.size() < kMagic.size()) file_.fail(0, "not a ROS bag (shorter than its version line)");
    file_.read(0, magic, kMagic.size());
    if (std::string_view(magic, kMagic.size()) != kMagic) {
      if (std::string_view(magic, 8) == "#ROSBAG ")
        file_.fail(0, "bag format '" + std::string(magic + 8, kMagic.size() - 9) +
                          "' is not supported (only V2.0; `rosbag fix` converts older bags)");
      file_.fail(0, "not a ROS bag (no '#ROSBAG V2.0' line)");
    }
    const Record header = read_record(file_, kMagic.size(), file_.size());
    expect_op(file_, header, kOpBagHeader, "bag header");
    return header;
  }

  // The chunk record `r`'s fields, checked: an uncompressed chunk's size is its data's, and no chunk claims
  // more than kMaxChunkBytes.
  Chunk checked_chunk(const Record& r) {
    Chunk c;
    c.pos = r.pos;
    c.compression = field(file_, r, "compression");
    c.size = field_int<uint32_t>(file_, r, "size");
    c.data_pos = r.data_pos;
    c.data_len = r.data_len;
    if (c.compression == "none" && c.size != c.data_len)
      file_.fail(c.pos, "uncompressed chunk of " + std::to_string(c.data_len) + " bytes says its size is " +
                            std::to_string(c.size));
    if (c.size > kMaxChunkBytes) file_.fail(c.pos, "chunk of " + std::to_string(c.size) + " bytes (corrupt)");
    return c;
  }

  // A connection record's id, topic, type and definition MD5.
  static std::pair<uint32_t, Connection> parse_connection(Bytes& src, const Record& r) {
    const uint32_t id = field_int<uint32_t>(src, r, "conn");
    Connection c;
    c.topic = field(src, r, "topic");
    // The data is a second field list: topic, type, md5sum, message_definition, ...
    std::string data(r.data_len, '\0');
    src.read_within(r.data_pos, r.end(), data.data(), data.size(), "connection data");
    Record d;
    d.pos = r.pos;
    d.op = kOpConnection;
    d.fields = parse_fields(src, r.pos, data);
    c.type = field(src, d, "type");
    c.md5 = field(src, d, "md5sum");
    return {id, std::move(c)};
  }

  // A bag repeats each connection record (in the chunk that first uses it, and after the chunks): the same
  // id with another topic, type or definition is an error.
  void add_scanned_connection(Bytes& src, const Record& r) {
    auto [id, c] = parse_connection(src, r);
    const auto [it, added] = connections_.emplace(id, c);
    if (!added && (it->second.topic != c.topic || it->second.type != c.type || it->second.md5 != c.md5))
      src.fail(r.pos, "connection " + std::to_string(id) + " is defined twice, differently");
  }

  // The chunk record `r` (complete in the file): its connections and message-data records.
  void scan_chunk(const Record& r, std::vector<Entry>& found) {
    const Chunk c = checked_chunk(r);
    InFileChunk in_file(file_, c.pos);
    std::optional<ChunkBytes> unpacked;
    Bytes* src = &in_file;
    uint64_t begin = c.data_pos, end = c.data_pos + c.data_len;
    if (c.compression != "none") {
      unpacked.emplace(file_.path(), c.pos, decompress(file_, c));
      src = &*unpacked;
      begin = 0;
      end = unpacked->size();
    }
    // Entries are kept only once the whole chunk has parsed: a chunk that fails part-way (the scan stops
    // there) must leave no entry pointing at it.
    const auto chunk = static_cast<uint32_t>(chunks_.size());
    std::vector<Entry> in_chunk;
    for (uint64_t at = begin; at < end;) {
      const Record m = read_record(*src, at, end);
      if (m.op == kOpConnection) {
        add_scanned_connection(*src, m);
      } else if (m.op == kOpMessageData) {
        const std::string& time = field(*src, m, "time");
        if (time.size() != 8) src->fail(m.pos, "message time of " + std::to_string(time.size()) + " bytes");
        const auto* t = reinterpret_cast<const uint8_t*>(time.data());
        in_chunk.push_back({{le32(t), le32(t + 4)},
                            chunk,
                            static_cast<uint32_t>(m.pos - begin),
                            field_int<uint32_t>(*src, m, "conn")});
      }
      at = m.end();
    }
    chunks_.push_back(c);
    found.insert(found.end(), in_chunk.begin(), in_chunk.end());
  }

  FileBytes file_;
  std::map<uint32_t, Connection> connections_;
  std::vector<Chunk> chunks_;
  std::vector<Entry> entries_;
  std::optional<ChunkBytes> cached_;
  uint32_t cached_chunk_ = std::numeric_limits<uint32_t>::max();
};

}  // namespace

RosBagCounts read_ros_bag(const fs::path& path, const RosBagTopics& topics, const RosBagHandlers& h,
                          const RosBagReadOptions& options) {
  if (!fs::exists(path)) fail(path, 0, "bag does not exist");
  enum Kind { kThermal, kLidar, kImuKind, kOdom, kNone };
  // The first of the topics a connection's topic equals (the order the handlers are listed in).
  const auto kind_of = [&](const std::string& topic) {
    const std::string* names[4] = {&topics.thermal, &topics.lidar, &topics.imu, &topics.odom};
    for (int k = 0; k < 4; ++k)
      if (!names[k]->empty() && *names[k] == topic) return static_cast<Kind>(k);
    return kNone;
  };
  BagReader bag(path);
  const auto wanted = [&](const Connection& c) { return kind_of(c.topic) != kNone; };
  RosBagCounts counts;
  if (options.reindex)
    counts.recovery = bag.scan(wanted);
  else
    bag.index(wanted);

  size_t index = 0;
  for (const Entry& e : bag.entries()) {
    ++index;
    const Connection& c = bag.connection(e.conn);
    const std::string where =
        "message " + std::to_string(index) + " on " + c.topic + " at " + std::to_string(e.time.seconds());
    const Kind kind = kind_of(c.topic);
    static const MessageType* types[4] = {&kImage, &kPointCloud2, &kImu, &kOdometry};
    const MessageType& type = *types[kind];
    if (c.type != type.name) fail(path, 0, where + ": type is " + c.type + ", expected " + type.name);
    if (c.md5 != type.md5)
      fail(path, 0,
           where + ": " + c.type + " with definition MD5 " + c.md5 + ", this reader decodes " + type.md5);
    const std::vector<uint8_t> bytes = bag.message(e);
    Wire w(bytes, where);
    Stamp stamp;
    // The header stamp; a zero stamp falls back to the bag's receive time.
    const auto t = [&] { return (stamp.zero() ? e.time : stamp).seconds(); };
    try {
      switch (kind) {
        case kThermal: {
          Image im = decode_image(w, stamp);
          ++counts.thermal;
          if (h.thermal) h.thermal(t(), std::move(im));
          break;
        }
        case kLidar: {
          PointCloud cloud = decode_point_cloud2(w, stamp);
          ++counts.lidar;
          if (h.lidar) h.lidar(t(), std::move(cloud));
          break;
        }
        case kImuKind: {
          ImuSample s = decode_imu(w, stamp);
          s.t_s = t();
          ++counts.imu;
          if (h.imu) h.imu(s);
          break;
        }
        case kOdom: {
          TumPose p = decode_odometry(w, stamp);
          p.t_s = t();
          ++counts.odom;
          if (h.odom) h.odom(p);
          break;
        }
        case kNone:
          break;
      }
    } catch (const MessageError& err) {
      fail(path, 0, err.what());
    }
  }
  return counts;
}

}  // namespace litgs::io
