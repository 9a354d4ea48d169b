#include "kernels/bench/gather_bench.h"

#include <stdexcept>
#include <string>

#include "kernels/subgroup_kernel.h"

namespace litgs::kernels {

const char* gather_read_name(GatherRead read) {
  switch (read) {
    case GatherRead::kStorageFloats:
      return "storage buffer, four float loads";
    case GatherRead::kStorageVec4:
      return "storage buffer, one vec4 load";
    case GatherRead::kTexelVec4:
      return "uniform texel buffer, one vec4 fetch";
  }
  return "?";
}

GatherBench::GatherBench(engine::Context& context, GatherRead read) {
  if (read == GatherRead::kTexelVec4)
    kernel_ =
        make_kernel(context, "bench/gather_texel", GATHER_BENCH_BINDING_COUNT, sizeof(GatherBenchParams), {},
                    {{GATHER_BENCH_BINDING_RECORDS, VK_FORMAT_R32G32B32A32_SFLOAT}});
  else
    kernel_ = make_kernel(context, "bench/gather_storage", GATHER_BENCH_BINDING_COUNT,
                          sizeof(GatherBenchParams), {{0, read == GatherRead::kStorageVec4 ? 1u : 0u}});
}

void GatherBench::record(engine::Sequence& sequence, const engine::DeviceArray<float>& records,
                         engine::DeviceArray<float>& sums, const GatherBenchParams& params) const {
  const size_t invocations = sums.size() / 4;
  if (params.records == 0 || records.size() < size_t{params.records} * 4 ||
      invocations % GATHER_BENCH_GROUP_SIZE != 0)
    throw std::invalid_argument("GatherBench: " + std::to_string(params.records) +
                                " records in an array of " + std::to_string(records.size()) + " floats, " +
                                std::to_string(invocations) +
                                " invocations (a positive count and a multiple of " +
                                std::to_string(GATHER_BENCH_GROUP_SIZE) + " are needed)");
  sequence.dispatch(*kernel_, {static_cast<uint32_t>(invocations / GATHER_BENCH_GROUP_SIZE)},
                    {{GATHER_BENCH_BINDING_RECORDS, &records.buffer(), engine::Access::kRead},
                     {GATHER_BENCH_BINDING_SUMS, &sums.buffer(), engine::Access::kWrite}},
                    params);
}

std::vector<double> gather_bench_reference(const std::vector<float>& records, uint32_t invocations,
                                           const GatherBenchParams& params) {
  std::vector<double> sums(size_t{invocations} * 4, 0.0);
  for (uint32_t i = 0; i < invocations; ++i)
    for (uint32_t r = 0; r < params.rounds; ++r) {
      const uint32_t j = gather_bench_index(i, r, params.records);
      for (int c = 0; c < 4; ++c) sums[size_t{i} * 4 + c] += records[size_t{j} * 4 + c];
    }
  return sums;
}

}  // namespace litgs::kernels
