#version 450
#extension GL_GOOGLE_include_directive : require
#extension GL_KHR_shader_subgroup_vote : require
#extension GL_KHR_shader_subgroup_ballot : require
#extension GL_KHR_shader_subgroup_arithmetic : require
#extension GL_KHR_shader_subgroup_shuffle : require
// One workgroup per 16x16 tile, one invocation per pixel: alpha-blend the tile's list front to back, one list
// segment per pass (splat_shared.h: a long list takes several passes, carrying the blend state).
#define SPLAT_RASTERIZE_PASS
#include "limits.h"
#include "splat/splat_shared.h"
#include "splat/splat_math.h"
#include "splat/splat_view.glsl"
#include "splat/footprint.glsl"
#include "splat/channels.glsl"

layout(local_size_x = SPLAT_TILE_SIZE, local_size_y = SPLAT_TILE_SIZE) in;

layout(std430, binding = FWD_BINDING_RANGES) readonly buffer Ranges { uvec2 ranges[]; };
// The per-entry reads, as texels (splat_shared.h).
layout(binding = FWD_BINDING_ISECT_IDS) uniform usamplerBuffer isect_ids;
layout(binding = FWD_BINDING_ISECT_GAUSSIAN) uniform usamplerBuffer isect_gaussian;
layout(binding = FWD_BINDING_CENTRES) uniform samplerBuffer centres;
layout(binding = FWD_BINDING_CONICS) uniform samplerBuffer conics;
layout(binding = FWD_BINDING_COLORS) uniform samplerBuffer colors;
layout(std430, binding = FWD_BINDING_IMAGE) buffer Image { float image[]; };
layout(std430, binding = FWD_BINDING_DEPTH) buffer Depth { float depth_out[]; };
layout(std430, binding = FWD_BINDING_ALPHA) buffer Alpha { float alpha_out[]; };
layout(std430, binding = FWD_BINDING_LAST) buffer Last { uint last_out[]; };
layout(std430, binding = FWD_BINDING_COUNTERS) buffer Counters { uint counters[]; };

// Each subgroup walks the tile's list on its own, SUBGROUP-wide chunk by chunk: lane k loads entry k of the
// chunk (two index fetches, two four-float fetches and the colour), a ballot keeps the entries whose 1/255
// footprint reaches the subgroup's pixels, and every lane then reads those entries from lane k by shuffle,
// in list order. No shared memory, no barriers; on CPU drivers a shuffle is a register permute.
void main() {
  const uvec2 pixel = tile_pixel();
  const bool inside = pixel.x < view.width && pixel.y < view.height;
  const uint tile = gl_WorkGroupID.y * view.tiles_x + gl_WorkGroupID.x;
  const uvec2 range = ranges[tile];
  const uint length = range.y - range.x;
  if (segment.begin >= length && segment.begin > 0u) return;  // the tile's list ended in an earlier pass
  const uint end = range.x + min(length, segment.end);
  const bool final_pass = length <= segment.end;
  const uint pix = pixel.y * view.width + pixel.x;
  const uint plane = view.width * view.height;

  const vec2 centre = vec2(pixel) + 0.5;
  const vec2 subgroup_lo = subgroupMin(centre), subgroup_hi = subgroupMax(centre);
  float T = 1.0;
  vec4 accum = vec4(0.0);  // a vector, not an array: CPU drivers spill dynamically indexed arrays
  float depth_sum = 0.0;
  uint last = 0u;
  uint contributions = 0u;
  bool done = !inside;
  if (segment.begin > 0u && inside) {  // continue from the previous pass's state
    T = alpha_out[pix];
    for (uint c = 0u; c < CHANNELS; ++c) accum[c] = image[c * plane + pix];
    depth_sum = depth_out[pix];
    last = last_out[pix];
    done = (last & FWD_LAST_DONE) != 0u;
    last &= ~FWD_LAST_DONE;
  }
  uint chunk = range.x + segment.begin;
  for (; chunk < end; chunk += gl_SubgroupSize) {
    if (subgroupAll(done)) break;
    // Lane k loads entry chunk + k.
    const uint entry = chunk + gl_SubgroupInvocationID;
    vec4 mean_extent = vec4(0.0), conic_opacity = vec4(0.0), color = vec4(0.0);
    float depth = 0.0;
    bool relevant = false;
    if (entry < end) {
      const int g = int(texelFetch(isect_gaussian, int(texelFetch(isect_ids, int(entry)).x)).x);
      const vec4 centre_g = texelFetch(centres, g);  // mean2d, depth, opacity
      const vec4 conic_g = texelFetch(conics, g);    // conic, alpha_reach(opacity)
      mean_extent = vec4(centre_g.xy, alpha_extent(conic_g.xyz, conic_g.w));
      conic_opacity = vec4(conic_g.xyz, centre_g.w);
      depth = centre_g.z;
      // The bounding box only: the backward's exact ellipse test (footprint_touches_box) costs the forward
      // more than the cheap blends it skips (measured on lavapipe, docs/experiments.md).
      relevant = footprint_reaches(mean_extent, subgroup_lo, subgroup_hi);
      if (relevant)
        for (uint c = 0u; c < CHANNELS; ++c) color[c] = texelFetch(colors, g * int(CHANNELS) + int(c)).x;
    }
    uvec4 todo = subgroupBallot(relevant);
    for (uint word = 0u; word < 4u; ++word) {
      while (todo[word] != 0u) {
        const uint k = 32u * word + uint(findLSB(todo[word]));
        todo[word] &= todo[word] - 1u;
        const vec4 me = subgroupShuffle(mean_extent, k);
        const vec4 co = subgroupShuffle(conic_opacity, k);
        const vec2 d = centre - me.xy;
        const float sigma = gaussian_sigma(co.xyz, d);
        const float alpha = min(float(SPLAT_ALPHA_MAX), co.w * exp(-min(sigma, SIGMA_CUTOFF)));
        const float next_T = T * (1.0 - alpha);
        // Predicated rather than branched: CPU drivers run the lanes as one SIMD register.
        const bool hit = !done && sigma >= 0.0 && alpha >= float(SPLAT_ALPHA_MIN);
        const bool stop = hit && next_T < float(SPLAT_T_MIN);
        done = done || stop;
        const float w = hit && !stop ? alpha * T : 0.0;
        accum = channels_fma(accum, w, channels_shuffle(color, k));
        depth_sum += w * subgroupShuffle(depth, k);
        T = hit && !stop ? next_T : T;
        last = hit && !stop ? chunk + k - range.x + 1u : last;
        contributions += hit && !stop ? 1u : 0u;
      }
    }
  }
  // A driver's loop limit (lavapipe: 65535 iterations per invocation) ends the walk early without an error:
  // count it, so that a pass sized wrongly for a device is seen (SPLAT_COUNTER_FORWARD_WALKS_CUT).
  if (chunk < end && !subgroupAll(done) && subgroupElect())
    atomicAdd(counters[SPLAT_COUNTER_FORWARD_WALKS_CUT], 1u);
  const uint subgroup_contributions = subgroupAdd(contributions);
  if (subgroupElect() && subgroup_contributions > 0u)
    atomicAdd(counters[SPLAT_COUNTER_CONTRIBUTIONS], subgroup_contributions);
  if (!inside) return;
  for (uint c = 0u; c < CHANNELS; ++c) image[c * plane + pix] = accum[c];
  if (!final_pass) {  // more of the list follows in the next pass
    alpha_out[pix] = T;
    depth_out[pix] = depth_sum;
    last_out[pix] = last | (done ? FWD_LAST_DONE : 0u);
    return;
  }
  const float a = 1.0 - T;
  alpha_out[pix] = a;
  depth_out[pix] = a >= float(SPLAT_MIN_DEPTH_WEIGHT) ? depth_sum / a : 0.0;
  last_out[pix] = last;
}
