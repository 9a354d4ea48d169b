// The per-kernel timings of the bench commands, as text and as JSON: one format for every benchmark.
#pragma once

#include <iomanip>
#include <nlohmann/json.hpp>
#include <ostream>
#include <vector>

#include "engine/sequence.h"

namespace litgs::tools {

// One line per kernel after a heading: name, dispatches and the summed GPU-timestamp milliseconds of the
// last run. Restores the stream's formatting flags and precision.
inline void print_kernel_profile(std::ostream& out, const std::vector<engine::KernelTime>& profile) {
  const std::ios_base::fmtflags flags = out.flags();
  const std::streamsize precision = out.precision();
  out << std::fixed << std::setprecision(2) << "  per kernel (last run, GPU timestamps):\n";
  for (const auto& k : profile)
    out << "    " << std::left << std::setw(42) << k.name << std::right << std::setw(3) << k.dispatches
        << "x " << std::setw(9) << k.ms << " ms\n";
  out.flags(flags);
  out.precision(precision);
}

// The JSON "kernels" array: [{"name", "ms", "dispatches"}] in profile order.
inline nlohmann::json kernel_profile_json(const std::vector<engine::KernelTime>& profile) {
  nlohmann::json kernels = nlohmann::json::array();
  for (const auto& k : profile)
    kernels.push_back({{"name", k.name}, {"ms", k.ms}, {"dispatches", k.dispatches}});
  return kernels;
}

}  // namespace litgs::tools
