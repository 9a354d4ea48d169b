#version 450
#extension GL_GOOGLE_include_directive : require
// Gathers four-float records as texels (kernels/bench/gather_shared.h): one fetch per record, the way the
// rasterize kernels read their per-entry attributes.
#include "bench/gather_shared.h"

layout(local_size_x = GATHER_BENCH_GROUP_SIZE) in;
layout(binding = GATHER_BENCH_BINDING_RECORDS) uniform samplerBuffer records;
layout(std430, binding = GATHER_BENCH_BINDING_SUMS) writeonly buffer Sums { vec4 sums[]; };
layout(push_constant) uniform Push { GatherBenchParams params; };

void main() {
  const uint i = gl_GlobalInvocationID.x;
  vec4 sum = vec4(0.0);
  for (uint r = 0u; r < params.rounds; ++r) sum += texelFetch(records, int(gather_bench_index(i, r, params.records)));
  sums[i] = sum;
}
