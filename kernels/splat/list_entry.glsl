// The record of one list entry (splat_shared.h, pack_list_entries.comp): vec4 (mean2d, extent), vec4 (conic,
// opacity), then a tail of colour[CHANNELS], depth and the Gaussian index's bits in one or two vec4.
// Needs splat_view.glsl (CHANNELS).
const uint ENTRY_VEC4S = SPLAT_ENTRY_VEC4S(CHANNELS);

// Float j of the tail (j a constant once CHANNELS is specialized).
float entry_tail(vec4 tail0, vec4 tail1, uint j) { return j < 4u ? tail0[j] : tail1[j - 4u]; }

void entry_unpack_tail(vec4 tail0, vec4 tail1, out vec4 color, out float depth, out uint g) {
  color = vec4(0.0);
  for (uint c = 0u; c < CHANNELS; ++c) color[c] = entry_tail(tail0, tail1, c);
  depth = entry_tail(tail0, tail1, CHANNELS);
  g = floatBitsToUint(entry_tail(tail0, tail1, CHANNELS + 1u));
}
