#include "io/control_points.h"

#include "io/error.h"
#include "io/text.h"

namespace litgs::io {

std::vector<ControlPoint> read_control_points_csv(const std::filesystem::path& path) {
  LineReader reader(path);
  std::string line;
  bool header = true;
  std::vector<ControlPoint> points;
  while (reader.next(line)) {
    if (trim(line).empty()) continue;
    const int64_t n = reader.line_number();
    const auto f = split_char(line, ',');
    if (f.size() != 5)
      fail(path, n, "expected 5 comma-separated fields (ID,X,Y,Z,accuracy), got " + std::to_string(f.size()));
    if (header) {  // the first line names the columns
      header = false;
      continue;
    }
    ControlPoint p;
    p.id = f[0];
    if (p.id.empty()) fail(path, n, "empty point id");
    for (const auto& q : points)
      if (q.id == p.id) fail(path, n, "point id '" + p.id + "' appears twice");
    p.p_world = {parse_double(f[1], path, n, "X"), parse_double(f[2], path, n, "Y"),
                 parse_double(f[3], path, n, "Z")};
    p.accuracy_m = parse_double(f[4], path, n, "accuracy");
    if (p.accuracy_m < 0) fail(path, n, "negative accuracy");
    points.push_back(p);
  }
  if (header) fail(path, 0, "empty file (expected a header line)");
  return points;
}

}  // namespace litgs::io
