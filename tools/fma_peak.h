// The device's measured floating-point peak (kernels/bench/fma_peak.comp): the yardstick bench render
// holds the rasterizer's useful FLOP/s against.
#pragma once

#include "engine/context.h"

namespace litgs::tools {

struct FmaPeak {
  double gflops = 0.0;  // best of the runs: 2 FLOPs per FMA lane
  double ms = 0.0;      // GPU time of that run
  double flops = 0.0;   // per run
};

// Runs the FMA-bound kernel `runs` times (after a warm-up) on enough workgroups to fill every thread of a
// CPU driver many times over, and returns the fastest run.
FmaPeak measure_fma_peak(engine::Context& context, int runs = 3);

}  // namespace litgs::tools
