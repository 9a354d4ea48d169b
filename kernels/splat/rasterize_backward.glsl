// One workgroup per tile, one invocation per pixel: walk the tile's list back to front from each pixel's
// last contributor, recovering transmittance by division (alpha <= 0.99 keeps it stable), and turn the
// pixel's upstream gradients into per-Gaussian gradients of (mean2d, conic, opacity, depth, colour).
//
// The including .comp defines SPLAT_BWD_MODE:
//   SPLAT_BWD_FLOAT_ATOMICS  per subgroup: subgroupAdd, then one atomicAdd per value (VK_EXT_shader_atomic_float)
//   SPLAT_BWD_CAS_ATOMICS    the same with a compare-and-swap loop, for devices without float atomics
//   SPLAT_BWD_DETERMINISTIC  the workgroup sums each entry in a fixed order and writes it to the
//                            intersection's own row; reduce_isect_grads.comp sums rows per Gaussian.
#define SPLAT_BWD_FLOAT_ATOMICS 0
#define SPLAT_BWD_CAS_ATOMICS 1
#define SPLAT_BWD_DETERMINISTIC 2

#include "limits.h"
#include "splat/splat_shared.h"
#include "splat/splat_math.h"
#include "splat/splat_view.glsl"

layout(local_size_x = SPLAT_TILE_SIZE, local_size_y = SPLAT_TILE_SIZE) in;

layout(std430, binding = BWD_BINDING_RANGES) readonly buffer Ranges { uvec2 ranges[]; };
layout(std430, binding = BWD_BINDING_ISECT_IDS) readonly buffer IsectIds { uint isect_ids[]; };
layout(std430, binding = BWD_BINDING_ISECT_GAUSSIAN) readonly buffer IsectGaussian { uint isect_gaussian[]; };
layout(std430, binding = BWD_BINDING_MEANS2D) readonly buffer Means2d { float means2d[]; };
layout(std430, binding = BWD_BINDING_CONICS) readonly buffer Conics { float conics[]; };
layout(std430, binding = BWD_BINDING_DEPTHS) readonly buffer Depths { float depths[]; };
layout(std430, binding = BWD_BINDING_OPACITIES) readonly buffer Opacities { float opacities[]; };
layout(std430, binding = BWD_BINDING_COLORS) readonly buffer Colors { float colors[]; };
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

#include "splat/footprint.glsl"

// 1: the exact gradient; 0: the expected depth's and the alpha map's gradients skip the opacity.
layout(constant_id = 2) const uint DEPTH_GRAD_TO_OPACITY = 1u;
#include "splat/channels.glsl"

// The gradient values of one entry for one pixel, as three vectors (no arrays: CPU drivers spill them):
// g0 = dL/d(mean2d.x, mean2d.y, conic.a, conic.b), g1 = dL/d(conic.c, opacity, depth, -), g2 = dL/d(colour).
struct EntryGrad {
  vec4 g0, g1, g2;
};

// One list entry, walked back to front. `in_walk`: the entry lies within this pixel's forward walk.
// Updates the running transmittance and the sums of what lies behind. Predicated, not branched.
EntryGrad entry_backward(vec2 centre, vec4 mean_extent, vec4 conic_opacity, vec4 color, float depth, bool in_walk,
                         float T_final, vec4 dL_dC, float dL_dN, float dL_dA, inout float T, inout vec4 acc_c,
                         inout float acc_z) {
  const vec2 d = centre - mean_extent.xy;
  const float sigma = gaussian_sigma(conic_opacity.xyz, d);
  const float vis = exp(-min(sigma, SIGMA_CUTOFF));
  const float raw = conic_opacity.w * vis;
  const float alpha = min(float(SPLAT_ALPHA_MAX), raw);
  const bool hit = in_walk && sigma >= 0.0 && alpha >= float(SPLAT_ALPHA_MIN);
  const float one_minus = 1.0 - alpha;
  const float Ti = T / one_minus;
  const float w = hit ? alpha * Ti : 0.0;
  const float dL_dalpha_image = channels_dot(dL_dC, channels_fma(channels_scale(-1.0 / one_minus, acc_c), Ti, color));
  const bool differentiable = hit && raw <= float(SPLAT_ALPHA_MAX);  // the 0.99 clamp has no gradient
  const float dL_dalpha = differentiable ? dL_dalpha_image + dL_dN * (depth * Ti - acc_z / one_minus) +
                                               dL_dA * T_final / one_minus
                                         : 0.0;
  // Without DEPTH_GRAD_TO_OPACITY the depth and alpha terms reach the footprint (mean, shape) but not the
  // opacity, which only the image decides (RasterizerOptions::depth_gradient_to_opacity).
  const float dL_dopacity = DEPTH_GRAD_TO_OPACITY != 0u ? dL_dalpha : (differentiable ? dL_dalpha_image : 0.0);
  const float dL_dsigma = -dL_dalpha * alpha;
  EntryGrad r;
  r.g0 = vec4(-dL_dsigma * (conic_opacity.x * d.x + conic_opacity.y * d.y),
              -dL_dsigma * (conic_opacity.y * d.x + conic_opacity.z * d.y), dL_dsigma * 0.5 * d.x * d.x,
              dL_dsigma * d.x * d.y);
  r.g1 = vec4(dL_dsigma * 0.5 * d.y * d.y, dL_dopacity * vis, w * dL_dN, 0.0);
  r.g2 = channels_scale(w, dL_dC);
  acc_c = channels_fma(acc_c, w, color);
  acc_z += w * depth;
  T = hit ? Ti : T;
  return r;
}

// Loads list entry `i`'s Gaussian.
void load_entry(uint i, out uint g, out vec4 mean_extent, out vec4 conic_opacity, out vec4 color, out float depth) {
  g = isect_gaussian[isect_ids[i]];
  const vec3 conic = vec3(conics[3 * g], conics[3 * g + 1], conics[3 * g + 2]);
  const float opacity = opacities[g];
  mean_extent = vec4(means2d[2 * g], means2d[2 * g + 1], alpha_extent(conic, opacity));
  conic_opacity = vec4(conic, opacity);
  color = vec4(0.0);
  for (uint c = 0u; c < CHANNELS; ++c) color[c] = colors[g * CHANNELS + c];
  depth = depths[g];
}

// Sums of three vectors over the subgroup, as a butterfly of XOR shuffles: on CPU drivers a shuffle with a
// uniform mask is a register permute, several times cheaper than subgroupAdd.
// With one channel the colour gradient rides in b.w (unused otherwise): two vectors instead of three.
void subgroup_sum3(inout vec4 a, inout vec4 b, inout vec4 c) {
  if (CHANNELS == 1u) {
    b.w = c.x;
    for (uint mask = 1u; mask < gl_SubgroupSize; mask <<= 1u) {
      a += subgroupShuffleXor(a, mask);
      b += subgroupShuffleXor(b, mask);
    }
    c = vec4(b.w, 0.0, 0.0, 0.0);
    b.w = 0.0;
    return;
  }
  for (uint mask = 1u; mask < gl_SubgroupSize; mask <<= 1u) {
    a += subgroupShuffleXor(a, mask);
    b += subgroupShuffleXor(b, mask);
    c += subgroupShuffleXor(c, mask);
  }
}

#if SPLAT_BWD_MODE == SPLAT_BWD_DETERMINISTIC
const uint MAX_SUBGROUPS = SPLAT_TILE_SIZE * SPLAT_TILE_SIZE;  // subgroups of one lane at worst
shared vec4 s_partial[MAX_SUBGROUPS][3];
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

void main() {
  const uvec2 pixel = gl_GlobalInvocationID.xy;
  const bool inside = pixel.x < view.width && pixel.y < view.height;
  const uint tile = gl_WorkGroupID.y * view.tiles_x + gl_WorkGroupID.x;
  const uvec2 range = ranges[tile];
  const uint pix = pixel.y * view.width + pixel.x;
  const uint plane = view.width * view.height;

  const vec2 centre = vec2(pixel) + 0.5;
  const uint my_last = inside ? fwd_last[pix] : 0u;
  const float A = inside ? fwd_alpha[pix] : 0.0;
  const float T_final = 1.0 - A;
  const bool has_depth = A >= float(SPLAT_MIN_DEPTH_WEIGHT);
  const float g_depth = inside ? grad_depth[pix] : 0.0;
  const float D = inside ? fwd_depth[pix] : 0.0;
  const float dL_dN = has_depth ? g_depth / A : 0.0;
  const float dL_dA = (inside ? grad_alpha[pix] : 0.0) - (has_depth ? g_depth * D / A : 0.0);
  vec4 dL_dC = vec4(0.0);
  for (uint c = 0u; c < CHANNELS; ++c) dL_dC[c] = inside ? grad_image[c * plane + pix] : 0.0;

  float T = T_final;
  vec4 acc_c = vec4(0.0);
  float acc_z = 0.0;

#if SPLAT_BWD_MODE == SPLAT_BWD_DETERMINISTIC
  // Every subgroup takes part in every entry's workgroup sum, in a fixed order: the same bits every run.
  if (gl_LocalInvocationIndex == 0u) s_walk = 0u;
  barrier();
  atomicMax(s_walk, my_last);
  barrier();
  const uint walk = s_walk;
  for (uint j = walk; j > 0u; --j) {
    uint g;
    vec4 mean_extent, conic_opacity, color;
    float depth;
    load_entry(range.x + j - 1u, g, mean_extent, conic_opacity, color, depth);
    const uint e = isect_ids[range.x + j - 1u];
    const EntryGrad r = entry_backward(centre, mean_extent, conic_opacity, color, depth, j <= my_last, T_final,
                                       dL_dC, dL_dN, dL_dA, T, acc_c, acc_z);
    vec4 s0 = r.g0, s1 = r.g1, s2 = r.g2;
    subgroup_sum3(s0, s1, s2);
    if (subgroupElect()) {
      s_partial[gl_SubgroupID][0] = s0;
      s_partial[gl_SubgroupID][1] = s1;
      s_partial[gl_SubgroupID][2] = s2;
    }
    barrier();
    if (gl_LocalInvocationIndex < 3u) {
      vec4 total = vec4(0.0);
      for (uint sg = 0u; sg < gl_NumSubgroups; ++sg) total += s_partial[sg][gl_LocalInvocationIndex];
      const uint base = e * GRAD2D_STRIDE;
      if (gl_LocalInvocationIndex == 0u)
        for (uint k = 0u; k < 4u; ++k) grad2d[base + k] = total[k];
      else if (gl_LocalInvocationIndex == 1u)
        for (uint k = 0u; k < 3u; ++k) grad2d[base + 4u + k] = total[k];
      else
        for (uint c = 0u; c < CHANNELS; ++c) grad2d[base + SPLAT_GRAD2D_FIXED + c] = total[c];
    }
    barrier();
  }
#else
  // Each subgroup walks back from its longest walk, a subgroup-wide chunk at a time: lane k loads entry k
  // of the chunk, a ballot keeps entries whose footprint reaches the subgroup, and the lanes take them from
  // lane k by shuffle, last to first. Lane k gathers its entry's subgroup sums and adds them once.
  const uint walk = subgroupMax(my_last);
  const uint S = gl_SubgroupSize;
  const vec2 subgroup_lo = subgroupMin(centre), subgroup_hi = subgroupMax(centre);
  for (uint chunk_end = walk; chunk_end > 0u; chunk_end = chunk_end > S ? chunk_end - S : 0u) {
    const uint chunk_start = chunk_end > S ? chunk_end - S : 0u;
    const uint rel = chunk_start + gl_SubgroupInvocationID;  // entry position within the tile's list
    uint g = 0u;
    vec4 mean_extent = vec4(0.0), conic_opacity = vec4(0.0), color = vec4(0.0);
    float depth = 0.0;
    bool relevant = false;
    if (rel < chunk_end) {
      load_entry(range.x + rel, g, mean_extent, conic_opacity, color, depth);
      relevant = footprint_reaches(mean_extent, subgroup_lo, subgroup_hi);
    }
    vec4 a0 = vec4(0.0), a1 = vec4(0.0), a2 = vec4(0.0);
    uvec4 todo = subgroupBallot(relevant);
    for (int word = 3; word >= 0; --word) {
      while (todo[word] != 0u) {
        const uint bit = uint(findMSB(todo[word]));
        todo[word] &= ~(1u << bit);
        const uint k = 32u * uint(word) + bit;
        const EntryGrad r = entry_backward(centre, subgroupShuffle(mean_extent, k), subgroupShuffle(conic_opacity, k),
                                           channels_shuffle(color, k), subgroupShuffle(depth, k),
                                           chunk_start + k < my_last, T_final, dL_dC, dL_dN, dL_dA, T, acc_c, acc_z);
        vec4 s0 = r.g0, s1 = r.g1, s2 = r.g2;
        subgroup_sum3(s0, s1, s2);
        if (gl_SubgroupInvocationID == k) {
          a0 += s0;
          a1 += s1;
          a2 += s2;
        }
      }
    }
    if (relevant) add_entry_grads(g, a0, a1, a2);
  }
#endif
}
