// Order statistics the stages share: medians of residuals, quantiles of pixel levels, and the outlier bound
// median + k * 1.4826 * MAD (k normal sigmas where the bulk is normal).
#pragma once

#include <vector>

namespace litgs::io {

// The q-quantile (q in [0, 1]) as the element at rank q (n - 1), rounded down; 0 for an empty vector.
double quantile(std::vector<double> values, double q);
// The element at rank n / 2 (the upper of the two middle ones for even n); 0 for an empty vector.
double median(std::vector<double> values);
// median + k * 1.4826 * (median absolute deviation), at least `floor`; `floor` for an empty vector.
double robust_upper_bound(const std::vector<double>& values, double k, double floor);

}  // namespace litgs::io
