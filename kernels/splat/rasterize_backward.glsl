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

#if SPLAT_BWD_MODE == SPLAT_BWD_DETERMINISTIC
const uint MAX_SUBGROUPS = (SPLAT_TILE_SIZE * SPLAT_TILE_SIZE);  // subgroups of one lane at worst
shared float s_partial[MAX_SUBGROUPS][SPLAT_GRAD2D_FIXED + SPLAT_MAX_CHANNELS];
shared uint s_walk;
#endif

void add_to(uint index, float value) {
#if SPLAT_BWD_MODE == SPLAT_BWD_FLOAT_ATOMICS
  atomicAdd(grad2d[index], value);
#elif SPLAT_BWD_MODE == SPLAT_BWD_CAS_ATOMICS
  uint expected = grad2d_bits[index];
  for (;;) {
    const uint desired = floatBitsToUint(uintBitsToFloat(expected) + value);
    const uint seen = atomicCompSwap(grad2d_bits[index], expected, desired);
    if (seen == expected) break;
    expected = seen;
  }
#endif
}

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
  float dL_dC[SPLAT_MAX_CHANNELS] = float[SPLAT_MAX_CHANNELS](0.0, 0.0, 0.0, 0.0);
  for (uint c = 0u; c < CHANNELS; ++c) dL_dC[c] = inside ? grad_image[c * plane + pix] : 0.0;

  // How far back to walk: this subgroup's longest walk (atomic modes) or the tile's (deterministic mode,
  // where every subgroup must take part in every step's workgroup sum).
#if SPLAT_BWD_MODE == SPLAT_BWD_DETERMINISTIC
  if (gl_LocalInvocationIndex == 0u) s_walk = 0u;
  barrier();
  atomicMax(s_walk, my_last);
  barrier();
  const uint walk = s_walk;
#else
  const uint walk = subgroupMax(my_last);
#endif

  float T = T_final;
  float acc_c[SPLAT_MAX_CHANNELS] = float[SPLAT_MAX_CHANNELS](0.0, 0.0, 0.0, 0.0);
  float acc_z = 0.0;
  for (uint j = walk; j > 0u; --j) {
    const uint e = isect_ids[range.x + j - 1u];
    const uint g = isect_gaussian[e];
    float v[SPLAT_GRAD2D_FIXED + SPLAT_MAX_CHANNELS];
    for (uint k = 0u; k < GRAD2D_STRIDE; ++k) v[k] = 0.0;
    bool contributes = false;
    if (j <= my_last) {
      const vec3 conic = vec3(conics[3 * g], conics[3 * g + 1], conics[3 * g + 2]);
      const vec2 d = centre - vec2(means2d[2 * g], means2d[2 * g + 1]);
      const float sigma = gaussian_sigma(conic, d);
      const float vis = exp(-sigma);
      const float raw = opacities[g] * vis;
      const float alpha = min(float(SPLAT_ALPHA_MAX), raw);
      if (sigma >= 0.0 && alpha >= float(SPLAT_ALPHA_MIN)) {
        contributes = true;
        const float one_minus = 1.0 - alpha;
        const float Ti = T / one_minus;
        const float w = alpha * Ti;
        float dL_dalpha = 0.0;
        for (uint c = 0u; c < CHANNELS; ++c) {
          const float color = colors[g * CHANNELS + c];
          v[SPLAT_GRAD2D_FIXED + c] = w * dL_dC[c];
          dL_dalpha += dL_dC[c] * (color * Ti - acc_c[c] / one_minus);
          acc_c[c] += w * color;
        }
        const float z = depths[g];
        v[6] = w * dL_dN;
        dL_dalpha += dL_dN * (z * Ti - acc_z / one_minus) + dL_dA * T_final / one_minus;
        acc_z += w * z;
        T = Ti;
        if (raw <= float(SPLAT_ALPHA_MAX)) {
          v[5] = dL_dalpha * vis;
          const float dL_dsigma = -dL_dalpha * alpha;
          v[2] = dL_dsigma * 0.5 * d.x * d.x;
          v[3] = dL_dsigma * d.x * d.y;
          v[4] = dL_dsigma * 0.5 * d.y * d.y;
          v[0] = -dL_dsigma * (conic.x * d.x + conic.y * d.y);
          v[1] = -dL_dsigma * (conic.y * d.x + conic.z * d.y);
        }
      }
    }
#if SPLAT_BWD_MODE == SPLAT_BWD_DETERMINISTIC
    for (uint k = 0u; k < GRAD2D_STRIDE; ++k) {
      const float sum = subgroupAdd(v[k]);
      if (subgroupElect()) s_partial[gl_SubgroupID][k] = sum;
    }
    barrier();
    // Fixed order over subgroups: the same sum every run.
    if (gl_LocalInvocationIndex < GRAD2D_STRIDE) {
      float total = 0.0;
      for (uint sg = 0u; sg < gl_NumSubgroups; ++sg) total += s_partial[sg][gl_LocalInvocationIndex];
      grad2d[e * GRAD2D_STRIDE + gl_LocalInvocationIndex] = total;
    }
    barrier();
#else
    if (subgroupAny(contributes)) {
      for (uint k = 0u; k < GRAD2D_STRIDE; ++k) {
        const float sum = subgroupAdd(v[k]);
        if (subgroupElect() && sum != 0.0) add_to(g * GRAD2D_STRIDE + k, sum);
      }
    }
#endif
  }
}
