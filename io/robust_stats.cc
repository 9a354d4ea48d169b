#include "io/robust_stats.h"

#include <algorithm>
#include <cmath>
#include <cstddef>

namespace litgs::io {

double quantile(std::vector<double> v, double q) {
  if (v.empty()) return 0;
  const auto at =
      v.begin() + static_cast<std::ptrdiff_t>(std::clamp(q, 0.0, 1.0) * static_cast<double>(v.size() - 1));
  std::nth_element(v.begin(), at, v.end());
  return *at;
}

double median(std::vector<double> v) {
  if (v.empty()) return 0;
  const auto at = v.begin() + static_cast<std::ptrdiff_t>(v.size() / 2);
  std::nth_element(v.begin(), at, v.end());
  return *at;
}

double robust_upper_bound(const std::vector<double>& values, double k, double floor) {
  if (values.empty()) return floor;
  const double m = median(values);
  std::vector<double> deviation;
  deviation.reserve(values.size());
  for (double x : values) deviation.push_back(std::abs(x - m));
  return std::max(floor, m + k * 1.4826 * median(std::move(deviation)));
}

}  // namespace litgs::io
