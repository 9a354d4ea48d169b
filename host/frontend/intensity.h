// Raw thermal counts to [0, 1]: a robust percentile stretch shared by a sequence (or by a sliding window of
// frames, for sensors whose level drifts). Used by the front end and by training, so both see the same
// mapping.
#pragma once

#include <cstddef>
#include <cstdint>
#include <vector>

namespace litgs::host::frontend {

// Counts of each raw value 0..65535.
using Histogram = std::vector<uint64_t>;
Histogram empty_histogram();
void add_to_histogram(Histogram& h, const std::vector<uint16_t>& values, size_t channels = 1);

// Raw values mapped to 0 and 1; anything outside is clamped.
struct Stretch {
  double low = 0, high = 1;
  float unit(double raw) const;  // (raw - low) / (high - low), clamped to [0, 1]
};

// The [low, high] percentiles of the histogram (the smallest value whose cumulative count reaches each).
// A histogram of one value (a constant image) gives [v, v + 1]: no division by zero, all pixels map to 0.
// std::invalid_argument if the percentiles are not 0 <= low < high <= 100 or the histogram is empty.
Stretch percentile_stretch(const Histogram& histogram, double low_percentile, double high_percentile);

// One stretch per frame from per-frame histograms: over all frames together (window 0), or over the frames
// i - window/2 .. i + window/2 (clipped to the sequence).
std::vector<Stretch> sequence_stretch(const std::vector<Histogram>& per_frame, double low_percentile,
                                      double high_percentile, size_t window);

}  // namespace litgs::host::frontend
