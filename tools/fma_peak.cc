#include "tools/fma_peak.h"

#include <algorithm>
#include <cstdint>

#include "engine/buffer.h"
#include "engine/sequence.h"
#include "kernels/subgroup_kernel.h"

namespace litgs::tools {

FmaPeak measure_fma_peak(engine::Context& context, int runs) {
  constexpr uint32_t kGroupSize = 64, kGroups = 512, kChains = 8;  // as in fma_peak.comp
  constexpr uint32_t kIterations = 4096;  // within lavapipe's 65535 loop iterations per invocation
  const uint32_t invocations = kGroupSize * kGroups;
  const auto kernel = kernels::make_kernel(context, "bench/fma_peak", 1, sizeof(uint32_t));
  engine::DeviceArray<float> sink(context, "bench: fma sink", invocations);
  engine::Sequence s(context);
  s.dispatch(*kernel, {kGroups, 1, 1}, {{0, &sink.buffer(), engine::Access::kWrite}}, kIterations);
  FmaPeak best;
  best.flops = double{invocations} * kIterations * kChains * 4 * 2;
  for (int r = 0; r <= runs; ++r) {
    s.submit_and_wait();
    if (r == 0) continue;  // warm-up
    const double ms = s.device_ms();
    if (best.ms == 0.0 || ms < best.ms) best.ms = ms;
  }
  best.gflops = best.ms > 0.0 ? best.flops / (best.ms * 1e6) : 0.0;
  return best;
}

}  // namespace litgs::tools
