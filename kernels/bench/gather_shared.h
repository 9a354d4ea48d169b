// The gather benchmark's contract (C++ and GLSL): kernels/bench/gather_*.comp read `rounds` four-float
// records per invocation at scattered indices and write their sum, so that the host can compare a storage
// buffer's loads with a uniform texel buffer's fetches (tools/gather_bench.h) and check what was read.
#ifndef LITGS_KERNELS_BENCH_GATHER_SHARED_H
#define LITGS_KERNELS_BENCH_GATHER_SHARED_H

#ifdef __cplusplus
#include <cstdint>
namespace litgs::kernels {
using uint = uint32_t;
#endif

#define GATHER_BENCH_GROUP_SIZE 64
#define GATHER_BENCH_BINDING_RECORDS 0  // [records][4] float (storage buffer, or texels R32G32B32A32_SFLOAT)
#define GATHER_BENCH_BINDING_SUMS 1     // [invocations][4] float (out)
#define GATHER_BENCH_BINDING_COUNT 2

struct GatherBenchParams {
  uint records;  // > 0
  uint rounds;   // records read per invocation
};

// The record invocation i reads in round r: scattered over the whole array (a multiplicative hash, with
// uint arithmetic wrapping the same way in C++ and GLSL).
#ifdef __cplusplus
inline uint gather_bench_index(uint i, uint r, uint records) {
  return (i * 2654435761u + r * 40503u) % records;
}
#else
uint gather_bench_index(uint i, uint r, uint records) {
  return (i * 2654435761u + r * 40503u) % records;
}
#endif

#ifdef __cplusplus
static_assert(sizeof(GatherBenchParams) <= 128);
}  // namespace litgs::kernels
#endif
#endif
