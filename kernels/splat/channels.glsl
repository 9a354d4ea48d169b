// Arithmetic on a colour vector that holds CHANNELS values (vec4 keeps it in registers on CPU drivers). With
// one channel (thermal) only .x is computed: float math cannot fold `x * 0.0` away (x may be inf or NaN), so
// a full vec4 would spend three quarters of its SIMD work, and of its shuffles, on zeros. CHANNELS is a
// specialization constant, so each select below is resolved when the pipeline is built.
vec4 channels_shuffle(vec4 c, uint lane) {
  return CHANNELS == 1u ? vec4(subgroupShuffle(c.x, lane), 0.0, 0.0, 0.0) : subgroupShuffle(c, lane);
}

// acc + w * c
vec4 channels_fma(vec4 acc, float w, vec4 c) {
  return CHANNELS == 1u ? vec4(acc.x + w * c.x, 0.0, 0.0, 0.0) : acc + w * c;
}

// a + b
vec4 channels_add(vec4 a, vec4 b) { return CHANNELS == 1u ? vec4(a.x + b.x, 0.0, 0.0, 0.0) : a + b; }

// w * c
vec4 channels_scale(float w, vec4 c) { return CHANNELS == 1u ? vec4(w * c.x, 0.0, 0.0, 0.0) : w * c; }

float channels_dot(vec4 a, vec4 b) { return CHANNELS == 1u ? a.x * b.x : dot(a, b); }
