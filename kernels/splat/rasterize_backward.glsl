// One workgroup per tile, one invocation per 2x4 pixels or per pixel (as rasterize_forward.comp):
// walk the tile's list back to front from each pixel's last contributor, recovering transmittance by division (alpha <= 0.99 keeps it stable), and turn the
// pixel's upstream gradients into per-Gaussian gradients of (mean2d, conic, opacity, depth, colour).
//
// The including .comp defines SPLAT_BWD_MODE:
//   SPLAT_BWD_FLOAT_ATOMICS  per subgroup: subgroupAdd, then one atomicAdd per value
//                            (VK_EXT_shader_atomic_float)
//   SPLAT_BWD_CAS_ATOMICS    the same with a compare-and-swap loop, for devices without float atomics
//   SPLAT_BWD_DETERMINISTIC  the workgroup sums each entry in a fixed order and writes it to the
//                            intersection's own row; reduce_isect_grads.comp sums rows per Gaussian.
#define SPLAT_BWD_FLOAT_ATOMICS 0
#define SPLAT_BWD_CAS_ATOMICS 1
#define SPLAT_BWD_DETERMINISTIC 2
// One list segment per pass, passes from the last segment to the first (splat_shared.h).
#define SPLAT_RASTERIZE_PASS

#include "limits.h"
#include "splat/splat_shared.h"
#include "splat/splat_math.h"
#include "splat/splat_view.glsl"

layout(std430, binding = BWD_BINDING_RANGES) readonly buffer Ranges { uvec2 ranges[]; };
// The per-entry reads, as texels (splat_shared.h).
layout(binding = BWD_BINDING_ISECT_IDS) uniform usamplerBuffer isect_ids;
layout(binding = BWD_BINDING_ISECT_GAUSSIAN) uniform usamplerBuffer isect_gaussian;
layout(binding = BWD_BINDING_CENTRES) uniform samplerBuffer centres;
layout(binding = BWD_BINDING_CONICS) uniform samplerBuffer conics;
layout(binding = BWD_BINDING_COLORS) uniform samplerBuffer colors;
layout(std430, binding = BWD_BINDING_DEPTH) readonly buffer FwdDepth { float fwd_depth[]; };
layout(std430, binding = BWD_BINDING_ALPHA) readonly buffer FwdAlpha { float fwd_alpha[]; };
layout(std430, binding = BWD_BINDING_LAST) readonly buffer FwdLast { uint fwd_last[]; };
layout(std430, binding = BWD_BINDING_GRAD_IMAGE) readonly buffer GradImage { float grad_image[]; };
layout(std430, binding = BWD_BINDING_GRAD_DEPTH) readonly buffer GradDepth { float grad_depth[]; };
layout(std430, binding = BWD_BINDING_GRAD_ALPHA) readonly buffer GradAlpha { float grad_alpha[]; };
#if SPLAT_BWD_MODE == SPLAT_BWD_CAS_ATOMICS
layout(std430, binding = BWD_BINDING_GRAD2D) buffer Grad2d { uint grad2d_bits[]; };
#else
layout(std430, binding = BWD_BINDING_GRAD2D) buffer Grad2d { float grad2d[]; };
#endif
layout(std430, binding = BWD_BINDING_STATE) buffer State { float state[]; };
layout(std430, binding = BWD_BINDING_COUNTERS) buffer Counters { uint counters[]; };

#include "splat/footprint.glsl"

// 1: the exact gradient; 0: the expected depth's and the alpha map's gradients skip the opacity.
layout(constant_id = 2) const uint DEPTH_GRAD_TO_OPACITY = 1u;
#include "splat/channels.glsl"

// The gradient values of one entry for one pixel, as three vectors (no arrays: CPU drivers spill them):
// g0 = dL/d(mean2d.x, mean2d.y, conic.a, conic.b), g1 = dL/d(conic.c, opacity, depth, -), g2 = dL/d(colour).
struct EntryGrad {
  vec4 g0, g1, g2;
};

// One pixel's backward state: its upstream gradients and, walking back to front, the transmittance and the
// sums of what lies behind. Eight per invocation, as separate variables (CPU drivers spill arrays).
struct PixelGrad {
  uint pix;    // index in the [H][W] planes
  uint last;   // entries the forward walked (0 outside the image)
  vec2 centre;
  float T_final;
  vec4 dL_dC;
  float dL_dN, dL_dA;
  float T;
  vec4 acc_c;
  float acc_z;
};

// One list entry (`entry`, counted from the list start), walked back to front, for one pixel: updates the
// pixel's running state. Predicated, not branched.
EntryGrad entry_backward(inout PixelGrad p, vec4 mean_extent, vec4 conic_opacity, vec4 color, float depth,
                         uint entry) {
  const bool in_walk = entry < p.last;  // the entry lies within this pixel's forward walk
  const vec2 centre = p.centre;
  const float T_final = p.T_final, dL_dN = p.dL_dN, dL_dA = p.dL_dA, T = p.T, acc_z = p.acc_z;
  const vec4 dL_dC = p.dL_dC, acc_c = p.acc_c;
  const vec2 d = centre - mean_extent.xy;
  const float sigma = gaussian_sigma(conic_opacity.xyz, d);
  const float vis = exp(-min(sigma, SIGMA_CUTOFF));
  const float raw = conic_opacity.w * vis;
  const float alpha = min(float(SPLAT_ALPHA_MAX), raw);
  const bool hit = in_walk && sigma >= 0.0 && alpha >= float(SPLAT_ALPHA_MIN);
  const float one_minus = 1.0 - alpha;
  const float Ti = T / one_minus;
  const float w = hit ? alpha * Ti : 0.0;
  const float dL_dalpha_image =
      channels_dot(dL_dC, channels_fma(channels_scale(-1.0 / one_minus, acc_c), Ti, color));
  const bool differentiable = hit && raw <= float(SPLAT_ALPHA_MAX);  // the 0.99 clamp has no gradient
  const float dL_dalpha = differentiable ? dL_dalpha_image + dL_dN * (depth * Ti - acc_z / one_minus) +
                                               dL_dA * T_final / one_minus
                                         : 0.0;
  // Without DEPTH_GRAD_TO_OPACITY the depth and alpha terms reach the footprint (mean, shape) but not the
  // opacity, which only the image decides (RasterizerOptions::depth_gradient_to_opacity).
  const float dL_dopacity =
      DEPTH_GRAD_TO_OPACITY != 0u ? dL_dalpha : (differentiable ? dL_dalpha_image : 0.0);
  const float dL_dsigma = -dL_dalpha * alpha;
  EntryGrad r;
  r.g0 = vec4(-dL_dsigma * (conic_opacity.x * d.x + conic_opacity.y * d.y),
              -dL_dsigma * (conic_opacity.y * d.x + conic_opacity.z * d.y), dL_dsigma * 0.5 * d.x * d.x,
              dL_dsigma * d.x * d.y);
  r.g1 = vec4(dL_dsigma * 0.5 * d.y * d.y, dL_dopacity * vis, w * dL_dN, 0.0);
  r.g2 = channels_scale(w, dL_dC);
  p.acc_c = channels_fma(acc_c, w, color);
  p.acc_z = acc_z + w * depth;
  p.T = hit ? Ti : T;
  return r;
}

#include "splat/list_entry.glsl"

// Sums of three vectors over the subgroup, as a butterfly of XOR shuffles: on CPU drivers a shuffle with a
// uniform mask is a register permute, several times cheaper than subgroupAdd.
// With one channel the colour gradient rides in b.w (unused otherwise): two vectors instead of three.
void subgroup_sum3(inout vec4 a, inout vec4 b, inout vec4 c) {
  if (CHANNELS == 1u) {
    b.w = c.x;
    for (uint mask = 1u; mask < subgroup_lanes(); mask <<= 1u) {
      a += subgroupShuffleXor(a, mask);
      b += subgroupShuffleXor(b, mask);
    }
    c = vec4(b.w, 0.0, 0.0, 0.0);
    b.w = 0.0;
    return;
  }
  for (uint mask = 1u; mask < subgroup_lanes(); mask <<= 1u) {
    a += subgroupShuffleXor(a, mask);
    b += subgroupShuffleXor(b, mask);
    c += subgroupShuffleXor(c, mask);
  }
}

#if SPLAT_BWD_MODE == SPLAT_BWD_DETERMINISTIC
// Per chunk, each lane's entry sums of each subgroup: [subgroup * S + lane][3] (subgroups x S = the
// workgroup's invocations).
shared vec4 s_partial[GROUP_INVOCATIONS * 3];
shared uint s_walk;
#else
void add_to(uint index, float value) {
  if (value == 0.0) return;
#if SPLAT_BWD_MODE == SPLAT_BWD_FLOAT_ATOMICS
  atomicAdd(grad2d[index], value);
#else
  uint expected = grad2d_bits[index];
  for (;;) {
    const uint desired = floatBitsToUint(uintBitsToFloat(expected) + value);
    const uint seen = atomicCompSwap(grad2d_bits[index], expected, desired);
    if (seen == expected) break;
    expected = seen;
  }
#endif
}

void add_entry_grads(uint g, vec4 a0, vec4 a1, vec4 a2) {
  const uint base = g * GRAD2D_STRIDE;
  for (uint k = 0u; k < 4u; ++k) add_to(base + k, a0[k]);
  for (uint k = 0u; k < 3u; ++k) add_to(base + 4u + k, a1[k]);
  for (uint c = 0u; c < CHANNELS; ++c) add_to(base + SPLAT_GRAD2D_FIXED + c, a2[c]);
}
#endif

// The entry sums of one chunk of the list, [chunk_start, chunk_end) relative to the list start, walked back
// to front: lane k loads entry chunk_start + k, a ballot keeps entries whose footprint reaches the subgroup,
// and the lanes take them from lane k by shuffle, last to first, each for its eight pixels. Lane k returns its
// entry's sums over the subgroup's pixels.
void chunk_backward(uint list_start, uint chunk_start, uint chunk_end, vec2 subgroup_lo, vec2 subgroup_hi,
                    inout PixelGrad p0, inout PixelGrad p1, inout PixelGrad p2, inout PixelGrad p3,
                    inout PixelGrad p4, inout PixelGrad p5, inout PixelGrad p6, inout PixelGrad p7, out uint g,
                    out bool relevant, out vec4 a0, out vec4 a1, out vec4 a2) {
  const uint rel = chunk_start + gl_SubgroupInvocationID;
  g = 0u;
  vec4 mean_extent = vec4(0.0), conic_opacity = vec4(0.0), color = vec4(0.0);
  float depth = 0.0;
  relevant = false;
  if (rel < chunk_end) {
    float reach;
    load_entry(list_start + rel, g, mean_extent, conic_opacity, depth, reach);
    relevant = footprint_reaches(mean_extent, subgroup_lo, subgroup_hi) &&
               footprint_touches_box(mean_extent, conic_opacity, reach, subgroup_lo, subgroup_hi);
    if (relevant) color = load_entry_color(g);
  }
  a0 = vec4(0.0);
  a1 = vec4(0.0);
  a2 = vec4(0.0);
  // Run as rasterize_forward.comp's walk: the body max(1, entries) times per word on a CPU driver.
  const uvec4 ballot = subgroupBallot(relevant);
  for (int word = int(ballot_words()) - 1; word >= 0; --word) {
    uint todo = ballot[word];
    if (todo != 0u) do {
      const uint bit = uint(findMSB(todo));
      todo &= ~(1u << bit);
      const uint k = 32u * uint(word) + bit;
      const vec4 me = subgroupShuffle(mean_extent, k), co = subgroupShuffle(conic_opacity, k);
      const vec4 col = channels_shuffle(color, k);
      const float dep = subgroupShuffle(depth, k);
      const uint entry = chunk_start + k;
      const EntryGrad r0 = entry_backward(p0, me, co, col, dep, entry);
      vec4 s0 = r0.g0, s1 = r0.g1, s2 = r0.g2;
      if (PIXEL_BLOCK == 8u) {
        const EntryGrad r1 = entry_backward(p1, me, co, col, dep, entry);
        const EntryGrad r2 = entry_backward(p2, me, co, col, dep, entry);
        const EntryGrad r3 = entry_backward(p3, me, co, col, dep, entry);
        const EntryGrad r4 = entry_backward(p4, me, co, col, dep, entry);
        const EntryGrad r5 = entry_backward(p5, me, co, col, dep, entry);
        const EntryGrad r6 = entry_backward(p6, me, co, col, dep, entry);
        const EntryGrad r7 = entry_backward(p7, me, co, col, dep, entry);
        s0 = ((r0.g0 + r1.g0) + (r2.g0 + r3.g0)) + ((r4.g0 + r5.g0) + (r6.g0 + r7.g0));
        s1 = ((r0.g1 + r1.g1) + (r2.g1 + r3.g1)) + ((r4.g1 + r5.g1) + (r6.g1 + r7.g1));
        s2 = channels_add(channels_add(channels_add(r0.g2, r1.g2), channels_add(r2.g2, r3.g2)),
                          channels_add(channels_add(r4.g2, r5.g2), channels_add(r6.g2, r7.g2)));
      }
      subgroup_sum3(s0, s1, s2);
      if (gl_SubgroupInvocationID == k) {
        a0 = s0;
        a1 = s1;
        a2 = s2;
      }
    } while (todo != 0u);
  }
}

// The next chunk's start going back from chunk_end, not below the segment's begin.
uint chunk_start_below(uint chunk_end) {
  const uint lanes = subgroup_lanes();
  return chunk_end > segment.begin + lanes ? chunk_end - lanes : segment.begin;
}

// The pixel's upstream gradients and its state at the start of this pass: the forward's results, or, for a
// pixel whose walk reaches past this segment, the state the previous pass (the segment after) stored.
PixelGrad start_pixel(uvec2 pixel, uint plane) {
  PixelGrad p;
  const bool inside = pixel.x < view.width && pixel.y < view.height;
  p.pix = pixel.y * view.width + pixel.x;
  p.centre = vec2(pixel) + 0.5;
  p.last = inside ? fwd_last[p.pix] : 0u;
  const float A = inside ? fwd_alpha[p.pix] : 0.0;
  p.T_final = 1.0 - A;
  const bool has_depth = A >= float(SPLAT_MIN_DEPTH_WEIGHT);
  const float g_depth = inside ? grad_depth[p.pix] : 0.0;
  const float D = inside ? fwd_depth[p.pix] : 0.0;
  p.dL_dN = has_depth ? g_depth / A : 0.0;
  p.dL_dA = (inside ? grad_alpha[p.pix] : 0.0) - (has_depth ? g_depth * D / A : 0.0);
  p.dL_dC = vec4(0.0);
  for (uint c = 0u; c < CHANNELS; ++c) p.dL_dC[c] = inside ? grad_image[c * plane + p.pix] : 0.0;
  p.T = p.T_final;
  p.acc_c = vec4(0.0);
  p.acc_z = 0.0;
  if (p.last > segment.end) {
    p.T = state[p.pix];
    p.acc_z = state[plane + p.pix];
    for (uint c = 0u; c < CHANNELS; ++c) p.acc_c[c] = state[(2u + c) * plane + p.pix];
  }
  return p;
}

// A pixel walked in this pass whose walk goes on in the next pass (the segment before) hands over its state.
void hand_over(PixelGrad p, uint plane) {
  if (segment.begin == 0u || p.last <= segment.begin) return;
  state[p.pix] = p.T;
  state[plane + p.pix] = p.acc_z;
  for (uint c = 0u; c < CHANNELS; ++c) state[(2u + c) * plane + p.pix] = p.acc_c[c];
}

void main() {
  const uvec2 base = block_origin();
  const uint tile = gl_WorkGroupID.y * view.tiles_x + gl_WorkGroupID.x;
  const uvec2 range = ranges[tile];
  const uint plane = view.width * view.height;
  PixelGrad p0 = start_pixel(base, plane);
  PixelGrad p1 = start_pixel(block_pixel(base, 1u, 0u), plane);
  PixelGrad p2 = start_pixel(block_pixel(base, 0u, 1u), plane);
  PixelGrad p3 = start_pixel(block_pixel(base, 1u, 1u), plane);
  PixelGrad p4 = start_pixel(block_pixel(base, 0u, 2u), plane);
  PixelGrad p5 = start_pixel(block_pixel(base, 1u, 2u), plane);
  PixelGrad p6 = start_pixel(block_pixel(base, 0u, 3u), plane);
  PixelGrad p7 = start_pixel(block_pixel(base, 1u, 3u), plane);
  const uint my_last = max(max(max(p0.last, p1.last), max(p2.last, p3.last)),
                           max(max(p4.last, p5.last), max(p6.last, p7.last)));
#if SPLAT_BWD_MODE != SPLAT_BWD_DETERMINISTIC
  if (subgroupAll(my_last <= segment.begin)) return;  // nothing of this subgroup's walks lies in this pass
#endif
  const vec2 subgroup_lo = subgroupMin(p0.centre);
  const vec2 subgroup_hi = subgroupMax(PIXEL_BLOCK == 8u ? p7.centre : p0.centre);
  uint chunk_end;

#if SPLAT_BWD_MODE == SPLAT_BWD_DETERMINISTIC
  // Every subgroup walks the workgroup's longest walk, chunk by chunk; per chunk each entry's sums over the
  // subgroups are added in a fixed order and written to the intersection's own row: the same bits every run.
  if (gl_LocalInvocationIndex == 0u) s_walk = 0u;
  barrier();
  atomicMax(s_walk, my_last);
  barrier();
  const uint walk = min(s_walk, segment.end);
  const uint S = subgroup_lanes();
  for (chunk_end = walk; chunk_end > segment.begin; chunk_end = chunk_start_below(chunk_end)) {
    const uint chunk_start = chunk_start_below(chunk_end);
    uint g;
    bool relevant;
    vec4 a0, a1, a2;
    chunk_backward(range.x, chunk_start, chunk_end, subgroup_lo, subgroup_hi, p0, p1, p2, p3, p4, p5, p6, p7, g, relevant, a0,
                   a1, a2);
    const uint slot = (gl_SubgroupID * S + gl_SubgroupInvocationID) * 3u;
    s_partial[slot] = a0;
    s_partial[slot + 1u] = a1;
    s_partial[slot + 2u] = a2;
    barrier();
    for (uint t = gl_LocalInvocationIndex; t < 3u * S; t += GROUP_INVOCATIONS) {
      const uint k = t / 3u, part = t % 3u;
      if (chunk_start + k >= chunk_end) continue;
      vec4 total = vec4(0.0);
      for (uint sg = 0u; sg < gl_NumSubgroups; ++sg) total += s_partial[(sg * S + k) * 3u + part];
      const uint base = texelFetch(isect_ids, int(range.x + chunk_start + k)).x * GRAD2D_STRIDE;
      if (part == 0u)
        for (uint v = 0u; v < 4u; ++v) grad2d[base + v] = total[v];
      else if (part == 1u)
        for (uint v = 0u; v < 3u; ++v) grad2d[base + 4u + v] = total[v];
      else
        for (uint c = 0u; c < CHANNELS; ++c) grad2d[base + SPLAT_GRAD2D_FIXED + c] = total[c];
    }
    barrier();
  }
  // A driver's loop limit ends the walk early without an error (see rasterize_forward.comp): count it.
  if (chunk_end > segment.begin && gl_LocalInvocationIndex == 0u)
    atomicAdd(counters[SPLAT_COUNTER_BACKWARD_WALKS_CUT], 1u);
#else
  // Each subgroup walks back from its own longest walk; lane k adds its entry's sums once.
  // do-while, not for: a CPU driver runs a loop's body once more, masked, when a for loop's test fails.
  chunk_end = min(subgroupMax(my_last), segment.end);
  if (chunk_end > segment.begin) do {
    uint g;
    bool relevant;
    vec4 a0, a1, a2;
    chunk_backward(range.x, chunk_start_below(chunk_end), chunk_end, subgroup_lo, subgroup_hi, p0, p1, p2, p3, p4, p5, p6, p7, g,
                   relevant, a0, a1, a2);
    if (relevant) add_entry_grads(g, a0, a1, a2);
    chunk_end = chunk_start_below(chunk_end);
  } while (chunk_end > segment.begin);
  if (chunk_end > segment.begin && subgroupElect()) atomicAdd(counters[SPLAT_COUNTER_BACKWARD_WALKS_CUT], 1u);
#endif

  hand_over(p0, plane);
  hand_over(p1, plane);
  hand_over(p2, plane);
  hand_over(p3, plane);
  hand_over(p4, plane);
  hand_over(p5, plane);
  hand_over(p6, plane);
  hand_over(p7, plane);
}
