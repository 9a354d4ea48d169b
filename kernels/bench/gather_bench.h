// Three ways of reading four-float records at scattered indices (kernels/bench/gather_*.comp): the yardstick
// for the rasterizer's per-entry reads (`litgs-engine bench gather`), and a check that texel reads return
// what a storage buffer holds.
#pragma once

#include <memory>
#include <vector>

#include "engine/buffer.h"
#include "engine/context.h"
#include "engine/kernel.h"
#include "engine/sequence.h"
#include "kernels/bench/gather_shared.h"

namespace litgs::kernels {

enum class GatherRead {
  kStorageFloats,  // four float loads from a storage buffer
  kStorageVec4,    // one vec4 load from a storage buffer
  kTexelVec4,      // one texel fetch from a uniform texel buffer (R32G32B32A32_SFLOAT)
};

const char* gather_read_name(GatherRead read);

class GatherBench {
 public:
  GatherBench(engine::Context& context, GatherRead read);

  // Records one dispatch: invocation i sums records[gather_bench_index(i, r, records)] over r < rounds into
  // sums[i]. records: [params.records][4]; sums: [invocations][4], invocations a multiple of
  // GATHER_BENCH_GROUP_SIZE.
  void record(engine::Sequence& sequence, const engine::DeviceArray<float>& records,
              engine::DeviceArray<float>& sums, const GatherBenchParams& params) const;

 private:
  std::unique_ptr<engine::Kernel> kernel_;
};

// The sums in double precision: [invocations][4].
std::vector<double> gather_bench_reference(const std::vector<float>& records, uint32_t invocations,
                                           const GatherBenchParams& params);

}  // namespace litgs::kernels
