#include "io/m2dgr_calib.h"

#include <Eigen/LU>

#include "io/error.h"
#include "io/text.h"

namespace litgs::io {
namespace {

enum class Item { kNone, kExtrinsic, kIntrinsic, kDistortion, kImageSize };

Item item_of(std::string_view comment) {
  if (comment.find("Extrinsic") != std::string_view::npos) return Item::kExtrinsic;
  if (comment.find("Intrinsic") != std::string_view::npos) return Item::kIntrinsic;
  if (comment.find("Distortion") != std::string_view::npos) return Item::kDistortion;
  if (comment.find("Image Size") != std::string_view::npos) return Item::kImageSize;
  return Item::kNone;
}

const std::string kFullWidthComma = "\xEF\xBC\x8C";  // U+FF0C in UTF-8

}  // namespace

M2dgrCamera read_m2dgr_camera(const std::filesystem::path& path, const std::string& block) {
  LineReader reader(path);
  M2dgrCamera cam;
  cam.block = std::string(trim(block));
  std::string line;
  bool inside = false, found = false;
  Item pending = Item::kNone;
  while (reader.next(line)) {
    const int64_t n = reader.line_number();
    const std::string_view t = trim(line);
    if (t.rfind("%%", 0) == 0) {
      if (inside) break;  // the next block starts
      inside = trim(t.substr(2)) == cam.block;
      found = found || inside;
      continue;
    }
    if (!inside) continue;
    if (t.rfind("%", 0) == 0) {
      const Item item = item_of(t);
      if (item != Item::kNone) pending = item;
      continue;
    }
    if (t.rfind("data:", 0) != 0) continue;  // blank lines and other keys ("gyr_n: ...") are not camera data

    // Gather "[ ... ]", possibly over several lines.
    const int64_t first_line = n;
    std::string text(trim(t.substr(5)));
    if (text.empty() || text.front() != '[') fail(path, n, "expected '[' after 'data:'");
    int64_t last_line = n;
    while (text.find(']') == std::string::npos) {
      std::string more;
      if (!reader.next(more)) fail(path, first_line, "'[' without a closing ']'");
      last_line = reader.line_number();
      text += "\n" + more;
    }
    const size_t close = text.find(']');
    if (!trim(std::string_view(text).substr(close + 1)).empty())
      fail(path, last_line, "text after the closing ']' (a stray ']' inside the list?)");
    const std::string_view inner = std::string_view(text).substr(1, close - 1);
    std::string body;
    int64_t line_here = first_line;
    for (size_t i = 0; i < inner.size(); ++i) {
      if (inner.compare(i, kFullWidthComma.size(), kFullWidthComma) == 0) {
        body.push_back(',');
        i += kFullWidthComma.size() - 1;
        std::string note = "line ";
        note += std::to_string(line_here);
        note += ": full-width comma (U+FF0C) read as ','";
        cam.notes.push_back(note);
      } else {
        if (inner[i] == '\n') ++line_here;
        body.push_back(inner[i]);
      }
    }
    std::vector<double> values;
    int64_t line_of_token = first_line;
    std::string token;
    const auto flush = [&] {
      if (!token.empty()) values.push_back(parse_double(token, path, line_of_token, "matrix entry"));
      token.clear();
    };
    for (char c : body) {
      if (c == ',' || c == ' ' || c == '\t' || c == '\n' || c == '\r') {
        flush();
        if (c == '\n') ++line_of_token;
      } else {
        token.push_back(c);
      }
    }
    flush();

    const auto expect_count = [&](std::initializer_list<size_t> counts, const char* what) {
      for (size_t c : counts)
        if (values.size() == c) return;
      fail(path, first_line, std::string(what) + ": " + std::to_string(values.size()) + " numbers");
    };
    switch (pending) {
      case Item::kExtrinsic: {
        expect_count({12, 16}, "extrinsic: expected 12 or 16 numbers, got");
        for (int i = 0; i < static_cast<int>(values.size()); ++i) cam.T_lidar_cam(i / 4, i % 4) = values[i];
        const Eigen::Matrix3d R = cam.T_lidar_cam.topLeftCorner<3, 3>();
        if ((R.transpose() * R - Eigen::Matrix3d::Identity()).norm() > 1e-6 || R.determinant() < 0 ||
            cam.T_lidar_cam.row(3) != Eigen::RowVector4d(0, 0, 0, 1))
          fail(path, first_line, "extrinsic is not a rigid transform");
        cam.has_extrinsic = true;
        break;
      }
      case Item::kIntrinsic: {
        expect_count({9}, "intrinsic: expected 9 numbers, got");
        Eigen::Matrix3d K;
        for (int i = 0; i < 9; ++i) K(i / 3, i % 3) = values[i];
        const bool upright = K(1, 0) == 0 && K(2, 0) == 0 && K(2, 1) == 0 && K(0, 1) == 0 && K(2, 2) == 1;
        const bool transposed = K(0, 1) == 0 && K(0, 2) == 0 && K(1, 2) == 0 && K(1, 0) == 0 &&
                                K(2, 2) == 1 && (K(2, 0) != 0 || K(2, 1) != 0);
        if (transposed) {
          K.transposeInPlace();
          cam.notes.push_back(
              "line " + std::to_string(first_line) +
              ": intrinsic matrix printed transposed ([fx 0 0; 0 fy 0; cx cy 1]), read as K^T");
        } else if (!upright) {
          fail(path, first_line, "intrinsic matrix is neither [fx 0 cx; 0 fy cy; 0 0 1] nor its transpose");
        }
        cam.fx = K(0, 0), cam.fy = K(1, 1), cam.cx = K(0, 2), cam.cy = K(1, 2);
        if (!(cam.fx > 0 && cam.fy > 0)) fail(path, first_line, "focal lengths must be positive");
        cam.has_intrinsics = true;
        break;
      }
      case Item::kDistortion:
        expect_count({4, 5}, "distortion: expected 4 or 5 numbers (k1 k2 p1 p2 [k3]), got");
        cam.distortion = values;
        break;
      case Item::kImageSize:
        expect_count({2}, "image size: expected 2 numbers, got");
        if (values[0] != std::floor(values[0]) || values[1] != std::floor(values[1]) || values[0] <= 0 ||
            values[1] <= 0)
          fail(path, first_line, "image size must be two positive integers");
        cam.width = static_cast<int>(values[0]);
        cam.height = static_cast<int>(values[1]);
        break;
      case Item::kNone:
        fail(path, first_line,
             "'data:' without a preceding '% Extrinsic/Intrinsic/Distortion/Image Size' comment");
    }
    pending = Item::kNone;
  }
  if (!found) fail(path, 0, "no block '%% " + cam.block + "'");
  return cam;
}

}  // namespace litgs::io
