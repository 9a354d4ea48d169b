#include "host/synth/level_drift.h"

#include <algorithm>
#include <cmath>

#include "io/atomic_file.h"
#include "io/text.h"

namespace litgs::host::synth {

std::vector<LevelDrift> level_drift(const std::vector<double>& t, size_t first_after_freeze) {
  std::vector<LevelDrift> d(t.size());
  if (t.empty()) return d;
  const double T = std::max(t.back() - t.front(), 1e-9);
  for (size_t i = 0; i < t.size(); ++i) {
    const double s = (t[i] - t.front()) / T;
    d[i].gain = 1 + 0.1 * s;
    d[i].offset_counts = 200 * (1 - std::exp(-3 * s)) - (i >= first_after_freeze ? 150.0 : 0.0);
  }
  return d;
}

void apply_level_drift(io::Image& raw, const LevelDrift& d) {
  for (auto& v : raw.data)
    v = static_cast<uint16_t>(std::clamp(std::lround(d.gain * v + d.offset_counts), 0l, 65535l));
}

void write_level_drift(const std::filesystem::path& path, const std::vector<double>& t,
                       const std::vector<LevelDrift>& d) {
  io::write_file_atomic(path, [&](std::ostream& os) {
    os << "# the sensor's level drift (synth --drift): raw' = gain raw + offset_counts; timestamp frame gain "
          "offset_counts\n";
    for (size_t i = 0; i < t.size(); ++i)
      os << io::format_double(t[i]) << " " << i << " " << io::format_double(d[i].gain) << " "
         << io::format_double(d[i].offset_counts) << "\n";
  });
}

}  // namespace litgs::host::synth
