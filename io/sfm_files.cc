#include "io/sfm_files.h"

#include <charconv>
#include <cmath>
#include <limits>
#include <ostream>
#include <stdexcept>

#include "io/atomic_file.h"
#include "io/error.h"
#include "io/text.h"

namespace litgs::io {
namespace fs = std::filesystem;
namespace {

constexpr const char* kFiles[] = {"images.txt", "keypoints.txt", "matches.txt", "tracks.txt", "points.txt"};

// Shortest text that reads back as exactly the float.
std::string format_float(float x) {
  char buffer[32];
  const auto r = std::to_chars(buffer, buffer + sizeof buffer, x);
  return std::string(buffer, r.ptr);
}

void check_observation(const SfmData& d, const SfmObservation& o, const char* where) {
  if (o.image >= d.images.size() || o.keypoint >= d.images[o.image].keypoints.size())
    throw std::invalid_argument(std::string("write_sfm: ") + where + " observation (" +
                                std::to_string(o.image) + ", " + std::to_string(o.keypoint) +
                                ") out of range");
}

void check(const SfmData& d) {
  for (const auto& p : d.pairs)
    for (const auto& m : p.matches) {
      check_observation(d, {p.image_a, m.keypoint_a}, "match");
      check_observation(d, {p.image_b, m.keypoint_b}, "match");
    }
  for (const auto& t : d.tracks) {
    for (const auto& o : t.observations) check_observation(d, o, "track");
    if (t.point >= static_cast<int64_t>(d.points.size()))
      throw std::invalid_argument("write_sfm: a track refers to point " + std::to_string(t.point));
  }
  for (const auto& p : d.points) {
    if (!p.xyz.allFinite() || !std::isfinite(p.error_px))
      throw std::invalid_argument("write_sfm: a point is not finite");
    for (const auto& o : p.observations) check_observation(d, o, "point");
  }
}

void write_observations(std::ostream& out, const std::vector<SfmObservation>& obs) {
  for (const auto& o : obs) out << ' ' << o.image << ' ' << o.keypoint;
}

// Parses the fields of one line; every index is checked against what was read before.
struct Parser {
  fs::path file;
  int64_t line = 0;
  std::vector<std::string_view> fields;

  void need(size_t n, bool at_least = false) const {
    if (at_least ? fields.size() < n : fields.size() != n)
      fail(file, line,
           "expected " + std::string(at_least ? "at least " : "") + std::to_string(n) + " fields, got " +
               std::to_string(fields.size()));
  }
  int64_t integer(size_t i, const char* what, int64_t lo, int64_t hi) const {
    return parse_int(fields[i], file, line, what, lo, hi);
  }
  double number(size_t i, const char* what) const { return parse_double(fields[i], file, line, what); }
  SfmObservation observation(size_t i, const SfmData& d) const {
    SfmObservation o;
    o.image = static_cast<uint32_t>(integer(i, "image", 0, static_cast<int64_t>(d.images.size()) - 1));
    o.keypoint = static_cast<uint32_t>(
        integer(i + 1, "keypoint", 0, static_cast<int64_t>(d.images[o.image].keypoints.size()) - 1));
    return o;
  }
  std::vector<SfmObservation> observations(size_t first, size_t count, const SfmData& d) const {
    need(first + 2 * count);
    std::vector<SfmObservation> obs;
    for (size_t k = 0; k < count; ++k) obs.push_back(observation(first + 2 * k, d));
    return obs;
  }
};

template <typename Fn>
void for_each_line(const fs::path& file, Fn&& fn) {
  LineReader reader(file);
  std::string text;
  Parser p{file, 0, {}};
  while (reader.next(text)) {
    if (is_blank_or_comment(text)) continue;
    p.line = reader.line_number();
    p.fields = split_ws(text);
    fn(p);
  }
}

constexpr int64_t kMaxIndex = std::numeric_limits<uint32_t>::max();

}  // namespace

bool has_sfm(const fs::path& dir) {
  for (const char* f : kFiles)
    if (!fs::is_regular_file(dir / f)) return false;
  return true;
}

void write_sfm(const fs::path& dir, const SfmData& d, const std::string& summary_json) {
  check(d);
  fs::create_directories(dir);
  write_file_atomic(dir / "images.txt", [&](std::ostream& out) {
    out << "# image_id frame keypoints frozen\n";
    for (size_t i = 0; i < d.images.size(); ++i)
      out << i << ' ' << d.images[i].frame << ' ' << d.images[i].keypoints.size() << ' '
          << (d.images[i].frozen ? 1 : 0) << '\n';
  });
  write_file_atomic(dir / "keypoints.txt", [&](std::ostream& out) {
    out << "# image_id keypoint_id x y size angle (pixels of the stored frame, top-left pixel centre 0,0)\n";
    for (size_t i = 0; i < d.images.size(); ++i)
      for (size_t k = 0; k < d.images[i].keypoints.size(); ++k) {
        const SfmKeypoint& kp = d.images[i].keypoints[k];
        out << i << ' ' << k << ' ' << format_float(kp.x) << ' ' << format_float(kp.y) << ' '
            << format_float(kp.size) << ' ' << format_float(kp.angle) << '\n';
      }
  });
  write_file_atomic(dir / "matches.txt", [&](std::ostream& out) {
    out << "# image_a image_b keypoint_a keypoint_b inlier\n";
    for (const auto& p : d.pairs)
      for (const auto& m : p.matches)
        out << p.image_a << ' ' << p.image_b << ' ' << m.keypoint_a << ' ' << m.keypoint_b << ' '
            << (m.inlier ? 1 : 0) << '\n';
  });
  write_file_atomic(dir / "tracks.txt", [&](std::ostream& out) {
    out << "# track_id point_id length (image keypoint)*length\n";
    for (size_t t = 0; t < d.tracks.size(); ++t) {
      out << t << ' ' << d.tracks[t].point << ' ' << d.tracks[t].observations.size();
      write_observations(out, d.tracks[t].observations);
      out << '\n';
    }
  });
  write_file_atomic(dir / "points.txt", [&](std::ostream& out) {
    out << "# point_id x y z error_px track_length (image keypoint)*track_length (scene frame, metres)\n";
    for (size_t i = 0; i < d.points.size(); ++i) {
      const SfmPoint& p = d.points[i];
      out << i << ' ' << format_double(p.xyz.x()) << ' ' << format_double(p.xyz.y()) << ' '
          << format_double(p.xyz.z()) << ' ' << format_double(p.error_px) << ' ' << p.observations.size();
      write_observations(out, p.observations);
      out << '\n';
    }
  });
  write_file_atomic(dir / "frontend.json", [&](std::ostream& out) { out << summary_json << '\n'; });
}

SfmData read_sfm(const fs::path& dir) {
  SfmData d;
  for_each_line(dir / "images.txt", [&](const Parser& p) {
    p.need(4);
    if (p.integer(0, "image_id", 0, kMaxIndex) != static_cast<int64_t>(d.images.size()))
      fail(p.file, p.line, "image ids must be 0, 1, 2, ... in order");
    SfmImage im;
    im.frame = std::string(p.fields[1]);
    im.keypoints.resize(static_cast<size_t>(p.integer(2, "keypoints", 0, kMaxIndex)));
    im.frozen = p.integer(3, "frozen", 0, 1) == 1;
    d.images.push_back(std::move(im));
  });
  std::vector<size_t> filled(d.images.size(), 0);
  for_each_line(dir / "keypoints.txt", [&](const Parser& p) {
    p.need(6);
    const auto i =
        static_cast<size_t>(p.integer(0, "image_id", 0, static_cast<int64_t>(d.images.size()) - 1));
    if (p.integer(1, "keypoint_id", 0, kMaxIndex) != static_cast<int64_t>(filled[i]) ||
        filled[i] >= d.images[i].keypoints.size())
      fail(p.file, p.line, "keypoint ids of an image must be 0, 1, 2, ... up to its count in images.txt");
    SfmKeypoint& kp = d.images[i].keypoints[filled[i]++];
    kp.x = static_cast<float>(p.number(2, "x"));
    kp.y = static_cast<float>(p.number(3, "y"));
    kp.size = static_cast<float>(p.number(4, "size"));
    kp.angle = static_cast<float>(p.number(5, "angle"));
  });
  for (size_t i = 0; i < d.images.size(); ++i)
    if (filled[i] != d.images[i].keypoints.size())
      fail(dir / "keypoints.txt", 0,
           "image " + std::to_string(i) + " has " + std::to_string(filled[i]) +
               " keypoints, images.txt says " + std::to_string(d.images[i].keypoints.size()));
  for_each_line(dir / "matches.txt", [&](const Parser& p) {
    p.need(5);
    const int64_t last_image = static_cast<int64_t>(d.images.size()) - 1;
    const auto ia = static_cast<uint32_t>(p.integer(0, "image_a", 0, last_image));
    const auto ib = static_cast<uint32_t>(p.integer(1, "image_b", 0, last_image));
    if (ia >= ib) fail(p.file, p.line, "image_a must be below image_b");
    SfmMatch m;
    m.keypoint_a = static_cast<uint32_t>(
        p.integer(2, "keypoint_a", 0, static_cast<int64_t>(d.images[ia].keypoints.size()) - 1));
    m.keypoint_b = static_cast<uint32_t>(
        p.integer(3, "keypoint_b", 0, static_cast<int64_t>(d.images[ib].keypoints.size()) - 1));
    m.inlier = p.integer(4, "inlier", 0, 1) == 1;
    if (d.pairs.empty() || d.pairs.back().image_a != ia || d.pairs.back().image_b != ib)
      d.pairs.push_back({ia, ib, {}});
    d.pairs.back().matches.push_back(m);
  });
  for_each_line(dir / "tracks.txt", [&](const Parser& p) {
    p.need(3, true);
    if (p.integer(0, "track_id", 0, kMaxIndex) != static_cast<int64_t>(d.tracks.size()))
      fail(p.file, p.line, "track ids must be 0, 1, 2, ... in order");
    SfmTrack t;
    t.point = p.integer(1, "point_id", -1, kMaxIndex);
    t.observations = p.observations(3, static_cast<size_t>(p.integer(2, "length", 0, kMaxIndex)), d);
    d.tracks.push_back(std::move(t));
  });
  for_each_line(dir / "points.txt", [&](const Parser& p) {
    p.need(6, true);
    if (p.integer(0, "point_id", 0, kMaxIndex) != static_cast<int64_t>(d.points.size()))
      fail(p.file, p.line, "point ids must be 0, 1, 2, ... in order");
    SfmPoint pt;
    pt.xyz = {p.number(1, "x"), p.number(2, "y"), p.number(3, "z")};
    pt.error_px = p.number(4, "error_px");
    pt.observations = p.observations(6, static_cast<size_t>(p.integer(5, "track_length", 0, kMaxIndex)), d);
    d.points.push_back(std::move(pt));
  });
  for (const auto& t : d.tracks)
    if (t.point >= static_cast<int64_t>(d.points.size()))
      fail(dir / "tracks.txt", 0,
           "a track refers to point " + std::to_string(t.point) + " beyond points.txt");
  return d;
}

}  // namespace litgs::io
