// The synthetic sensor's level drift (SynthOptions::drift): an uncooled microbolometer warms up after
// power-on and its raw counts drift slowly in gain and offset; its non-uniformity correction (NUC) then
// shifts the offset at once. Frame f at time t (seconds after the first frame; T the sequence's duration)
// reads
//   raw' = gain(t) raw + offset(t),  gain(t) = 1 + 0.1 t / T,
//   offset(t) = 200 (1 - exp(-3 t / T)) counts, minus 150 counts from the first frame after the first freeze.
// The 200-count rise is of the order of DUNR's (about 180 counts in its first minute).
#pragma once

#include <cstdint>
#include <filesystem>
#include <vector>

#include "io/image.h"

namespace litgs::host::synth {

struct LevelDrift {
  double gain = 1, offset_counts = 0;
};

// Per frame: `times_s` every frame's time, `first_after_freeze` the index of the first frame after the first
// freeze (frames.size() or more: no jump).
std::vector<LevelDrift> level_drift(const std::vector<double>& times_s, size_t first_after_freeze);
// raw' = gain raw + offset, rounded and clamped to 16 bits.
void apply_level_drift(io::Image& raw, const LevelDrift& drift);
// gt/levels.txt: "timestamp frame gain offset_counts" per frame (a frozen frame: its source frame's).
void write_level_drift(const std::filesystem::path& path, const std::vector<double>& times_s,
                       const std::vector<LevelDrift>& drift);

}  // namespace litgs::host::synth
