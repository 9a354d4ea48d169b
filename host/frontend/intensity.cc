#include "host/frontend/intensity.h"

#include <algorithm>
#include <stdexcept>
#include <string>

namespace litgs::host::frontend {

Histogram empty_histogram() {
  return Histogram(65536, 0);
}

void add_to_histogram(Histogram& h, const std::vector<uint16_t>& values, size_t channels) {
  for (size_t i = 0; i < values.size(); i += channels) ++h[values[i]];
}

float Stretch::unit(double raw) const {
  return static_cast<float>(std::clamp((raw - low) / (high - low), 0.0, 1.0));
}

Stretch percentile_stretch(const Histogram& histogram, double low_percentile, double high_percentile) {
  if (!(low_percentile >= 0 && low_percentile < high_percentile && high_percentile <= 100))
    throw std::invalid_argument("percentile stretch: percentiles must satisfy 0 <= low < high <= 100 (got " +
                                std::to_string(low_percentile) + ", " + std::to_string(high_percentile) +
                                ")");
  uint64_t total = 0;
  for (uint64_t c : histogram) total += c;
  if (total == 0) throw std::invalid_argument("percentile stretch: no pixels");
  auto value_at = [&](double pct) {
    const double target = pct / 100.0 * static_cast<double>(total);
    uint64_t seen = 0;
    for (size_t v = 0; v < histogram.size(); ++v) {
      seen += histogram[v];
      if (seen > 0 && static_cast<double>(seen) >= target) return static_cast<double>(v);  // 0: the minimum
    }
    return static_cast<double>(histogram.size() - 1);
  };
  Stretch s{value_at(low_percentile), value_at(high_percentile)};
  if (!(s.high > s.low)) s.high = s.low + 1;
  return s;
}

std::vector<Stretch> sequence_stretch(const std::vector<Histogram>& per_frame, double low_percentile,
                                      double high_percentile, size_t window) {
  std::vector<Stretch> out;
  if (per_frame.empty()) return out;
  if (window == 0) {
    Histogram all = empty_histogram();
    for (const Histogram& h : per_frame)
      for (size_t v = 0; v < h.size(); ++v) all[v] += h[v];
    return std::vector<Stretch>(per_frame.size(), percentile_stretch(all, low_percentile, high_percentile));
  }
  const size_t half = window / 2;
  for (size_t i = 0; i < per_frame.size(); ++i) {
    Histogram sum = empty_histogram();
    const size_t first = i > half ? i - half : 0, last = std::min(per_frame.size() - 1, i + half);
    for (size_t j = first; j <= last; ++j)
      for (size_t v = 0; v < sum.size(); ++v) sum[v] += per_frame[j][v];
    out.push_back(percentile_stretch(sum, low_percentile, high_percentile));
  }
  return out;
}

}  // namespace litgs::host::frontend
