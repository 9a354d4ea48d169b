#version 450
#extension GL_GOOGLE_include_directive : require
// Gathers four-float records from a storage buffer (kernels/bench/gather_shared.h): as one vec4 load per
// record, or (VEC4_LOADS = 0) as four float loads, the way the rasterizer read its attributes before they
// became texel fetches (docs/experiments.md, issue 18).
#include "bench/gather_shared.h"

layout(local_size_x = GATHER_BENCH_GROUP_SIZE) in;
layout(std430, binding = GATHER_BENCH_BINDING_RECORDS) readonly buffer Records { vec4 records[]; };
layout(std430, binding = GATHER_BENCH_BINDING_RECORDS) readonly buffer RecordFloats { float record_floats[]; };
layout(std430, binding = GATHER_BENCH_BINDING_SUMS) writeonly buffer Sums { vec4 sums[]; };
layout(push_constant) uniform Push { GatherBenchParams params; };
layout(constant_id = 0) const uint VEC4_LOADS = 1u;

void main() {
  const uint i = gl_GlobalInvocationID.x;
  vec4 sum = vec4(0.0);
  for (uint r = 0u; r < params.rounds; ++r) {
    const uint j = gather_bench_index(i, r, params.records);
    sum += VEC4_LOADS != 0u ? records[j]
                            : vec4(record_floats[4u * j], record_floats[4u * j + 1u], record_floats[4u * j + 2u],
                                   record_floats[4u * j + 3u]);
  }
  sums[i] = sum;
}
