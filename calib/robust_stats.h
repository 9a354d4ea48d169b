// Order statistics the detectors and solvers share: medians of residuals, quantiles of pixel levels.
#pragma once

#include <vector>

namespace litgs::calib {

// The q-quantile (q in [0, 1]) as the element at rank q (n - 1), rounded down; 0 for an empty vector.
double quantile(std::vector<double> values, double q);
// The element at rank n / 2 (the upper of the two middle ones for even n); 0 for an empty vector.
double median(std::vector<double> values);

}  // namespace litgs::calib
