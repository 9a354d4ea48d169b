#version 450
// The device's floating-point peak, measured: every invocation runs FMA_CHAINS independent chains of vec4
// fused multiply-adds for `iterations` rounds (enough independent work to hide each FMA's latency), then
// writes one sum so that nothing is optimized away. FLOPs = invocations * iterations * FMA_CHAINS * 4 * 2.
// The rates (0.999..., 1e-7) keep every value finite and normal for any iteration count.
layout(local_size_x = 64) in;
layout(std430, binding = 0) writeonly buffer Sink { float sink[]; };
layout(push_constant) uniform Push { uint iterations; };

const uint FMA_CHAINS = 8u;  // also in tools/fma_peak.cc

void main() {
  const float seed = float(gl_GlobalInvocationID.x) * 1e-6;
  vec4 a0 = vec4(seed), a1 = a0 + 1.0, a2 = a0 + 2.0, a3 = a0 + 3.0;
  vec4 a4 = a0 + 4.0, a5 = a0 + 5.0, a6 = a0 + 6.0, a7 = a0 + 7.0;
  const vec4 m = vec4(0.9999999), c = vec4(1e-7);
  for (uint i = 0u; i < iterations; ++i) {
    a0 = fma(a0, m, c);
    a1 = fma(a1, m, c);
    a2 = fma(a2, m, c);
    a3 = fma(a3, m, c);
    a4 = fma(a4, m, c);
    a5 = fma(a5, m, c);
    a6 = fma(a6, m, c);
    a7 = fma(a7, m, c);
  }
  const vec4 s = ((a0 + a1) + (a2 + a3)) + ((a4 + a5) + (a6 + a7));
  sink[gl_GlobalInvocationID.x] = s.x + s.y + s.z + s.w;
}
