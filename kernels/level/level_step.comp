#version 450
#extension GL_GOOGLE_include_directive : require
// One workgroup: the level parameters' gradient (the block sums of level_backward, in a fixed order, plus the
// regularizers' gradients), then Adam (bias-corrected as torch.optim.Adam) on the frame's log-gain and offset
// and on the shared vignetting (a row whose update is not finite is left unchanged and counted), then the
// trained frames re-centred on their mean (level_shared.h).
#include "limits.h"
#include "level/level_shared.h"

layout(local_size_x = 256) in;
layout(std430, binding = LEVEL_STEP_BINDING_SUMS) readonly buffer Sums { vec4 sums[]; };
layout(std430, binding = LEVEL_STEP_BINDING_STATE) buffer State { float state[]; };
layout(push_constant) uniform Push { LevelStepParams p; };

shared vec4 partial[256];

bool finite_value(float x) { return (floatBitsToUint(x) & 0x7f800000u) != 0x7f800000u; }

// Adam on the two parameters of `row` with gradient g and rates lr, each clamped to [-limit, limit] where
// limit > 0; true if the result is finite and stored.
bool adam2(uint row, vec2 g, vec2 lr, vec2 limit) {
  const float steps = state[row + LEVEL_STEPS] + 1.0;
  const vec2 m = p.beta1 * vec2(state[row + 2], state[row + 3]) + (1.0 - p.beta1) * g;
  const vec2 v = p.beta2 * vec2(state[row + 4], state[row + 5]) + (1.0 - p.beta2) * (g * g);
  const float bc1 = 1.0 - pow(p.beta1, steps);
  const float bc2 = 1.0 - pow(p.beta2, steps);
  const vec2 x = vec2(state[row], state[row + 1]) - (lr / bc1) * (m / (sqrt(v) / sqrt(bc2) + p.eps));
  bool ok = true;
  for (int i = 0; i < 2; ++i)
    ok = ok && finite_value(g[i]) && finite_value(m[i]) && finite_value(v[i]) && finite_value(x[i]);
  if (!ok) return false;
  state[row] = limit.x > 0.0 ? clamp(x.x, -limit.x, limit.x) : x.x;
  state[row + 1] = limit.y > 0.0 ? clamp(x.y, -limit.y, limit.y) : x.y;
  state[row + 2] = m.x;
  state[row + 3] = m.y;
  state[row + 4] = v.x;
  state[row + 5] = v.y;
  state[row + LEVEL_STEPS] = steps;
  return true;
}

void main() {
  const uint t = gl_LocalInvocationID.x;
  vec4 s = vec4(0.0);
  // p.blocks <= 256 * MAX_BATCHES_PER_WORKGROUP (checked on the host), within lavapipe's loop budget.
  for (uint i = t; i < p.blocks; i += 256u) s += sums[i];
  partial[t] = s;
  barrier();
  for (uint stride = 128u; stride > 0u; stride >>= 1u) {
    if (t < stride) partial[t] += partial[t + stride];
    barrier();
  }
  const uint shared_row = p.frames * LEVEL_STRIDE;
  if (t == 0u) {
    const vec4 total = partial[0];
    uint skipped = 0u;
    const uint row = p.frame * LEVEL_STRIDE;
    const vec2 x = vec2(state[row], state[row + 1]);
    vec2 g = total.xy + 2.0 * p.lambda_identity * x;
    for (int side = 0; side < 2; ++side) {
      const int n = side == 0 ? p.prev : p.next;
      if (n < 0) continue;
      const uint nrow = uint(n) * LEVEL_STRIDE;
      g += 2.0 * p.lambda_smooth * (x - vec2(state[nrow], state[nrow + 1]));
    }
    const vec2 limit = vec2(LEVEL_LOG_GAIN_LIMIT, 0.0);
    if (!adam2(row, g, vec2(p.lr_log_gain, p.lr_offset), limit)) skipped += 1u;
    if (p.vignetting != 0u) {
      const vec2 k = vec2(state[shared_row], state[shared_row + 1]);
      const vec2 gk = total.zw + 2.0 * p.lambda_identity * k;
      if (!adam2(shared_row, gk, vec2(p.lr_vignetting), vec2(LEVEL_VIGNETTING_LIMIT))) skipped += 1u;
    }
    state[shared_row + LEVEL_SKIPS] += float(skipped);
  }
  if (p.center == 0u) return;  // uniform: every invocation returns
  memoryBarrierBuffer();
  barrier();
  // The trained frames' mean log-gain (each clamped) and mean offset, summed in a fixed order.
  vec4 c = vec4(0.0);
  for (uint f = t; f < p.frames; f += 256u) {
    const uint r = f * LEVEL_STRIDE;
    if (state[r + LEVEL_TRAINED] != 0.0)
      c += vec4(clamp(state[r], -LEVEL_LOG_GAIN_LIMIT, LEVEL_LOG_GAIN_LIMIT), state[r + 1], 1.0, 0.0);
  }
  partial[t] = c;
  barrier();
  for (uint stride = 128u; stride > 0u; stride >>= 1u) {
    if (t < stride) partial[t] += partial[t + stride];
    barrier();
  }
  const vec4 sum = partial[0];
  if (sum.z == 0.0) return;
  const vec2 mean = sum.xy / sum.z;
  for (uint f = t; f < p.frames; f += 256u) {
    const uint r = f * LEVEL_STRIDE;
    if (state[r + LEVEL_TRAINED] == 0.0) continue;
    state[r] = clamp(state[r], -LEVEL_LOG_GAIN_LIMIT, LEVEL_LOG_GAIN_LIMIT) - mean.x;
    state[r + 1] -= mean.y;
  }
}
