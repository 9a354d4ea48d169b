#include "calib/robust_stats.h"

#include <algorithm>
#include <cstddef>

namespace litgs::calib {

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

}  // namespace litgs::calib
