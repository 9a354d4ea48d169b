#version 450
#extension GL_GOOGLE_include_directive : require
#extension GL_KHR_shader_subgroup_vote : require
#extension GL_KHR_shader_subgroup_ballot : require
#extension GL_KHR_shader_subgroup_arithmetic : require
#extension GL_KHR_shader_subgroup_shuffle : require
// One workgroup per 16x16 tile, one invocation per 2x4 pixels (CPU devices) or per pixel (GPUs;
// footprint.glsl): alpha-blend the tile's list front to back, one list segment per pass (splat_shared.h: a
// long list takes several passes, carrying the blend state).
#define SPLAT_RASTERIZE_PASS
#include "limits.h"
#include "splat/splat_shared.h"
#include "splat/splat_math.h"
#include "splat/splat_view.glsl"
#include "splat/footprint.glsl"
#include "splat/channels.glsl"

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
#include "splat/list_entry.glsl"

// Each subgroup walks the tile's list on its own, a chunk of subgroup_lanes() entries at a time: lane k loads entry k of the
// chunk (two index fetches, two four-float fetches and the colour), a ballot keeps the entries whose 1/255
// footprint reaches the subgroup's pixels, and every lane then reads those entries from lane k by shuffle,
// in list order, and blends each into its eight pixels. No shared memory, no barriers; on CPU drivers a
// shuffle is a register permute. Eight pixels per invocation (footprint.glsl block_origin): an eighth of the
// subgroups reads the tile's list, and each entry taken by shuffle serves eight pixels: on a CPU device that
// roughly halves the forward's time against one pixel per invocation (docs/experiments.md, "four pixels per
// invocation" and "eight pixels per invocation", issue 18).

// One pixel's blend state. Up to eight per invocation, as separate variables (CPU drivers spill arrays);
// with one pixel per invocation s1..s7 lie outside the image and are never blended.
struct PixelState {
  uvec2 pixel;
  bool inside;
  vec2 centre;
  float T;     // transmittance
  vec4 accum;  // a vector, not an array: CPU drivers spill dynamically indexed arrays
  float depth_sum;
  uint last;
  uint contributions;
  bool done;
};

// The state at the start of this pass: empty, or the previous pass's (held in the output buffers).
PixelState start_pixel(uvec2 pixel, uint plane) {
  PixelState s;
  s.pixel = pixel;
  s.inside = pixel.x < view.width && pixel.y < view.height;
  s.centre = vec2(pixel) + 0.5;
  s.T = 1.0;
  s.accum = vec4(0.0);
  s.depth_sum = 0.0;
  s.last = 0u;
  s.contributions = 0u;
  s.done = !s.inside;
  if (segment.begin > 0u && s.inside) {
    const uint pix = pixel.y * view.width + pixel.x;
    s.T = alpha_out[pix];
    for (uint c = 0u; c < CHANNELS; ++c) s.accum[c] = image[c * plane + pix];
    s.depth_sum = depth_out[pix];
    s.last = last_out[pix];
    s.done = (s.last & FWD_LAST_DONE) != 0u;
    s.last &= ~FWD_LAST_DONE;
  }
  return s;
}

// Blends list entry `position` (1-based within the tile's list) into the pixel. Predicated rather than
// branched: CPU drivers run the lanes as one SIMD register.
void blend(inout PixelState s, vec4 me, vec4 co, vec4 color, float depth, uint position) {
  const vec2 d = s.centre - me.xy;
  const float sigma = gaussian_sigma(co.xyz, d);
  const float alpha = min(float(SPLAT_ALPHA_MAX), co.w * exp(-min(sigma, SIGMA_CUTOFF)));
  const float next_T = s.T * (1.0 - alpha);
  const bool hit = !s.done && sigma >= 0.0 && alpha >= float(SPLAT_ALPHA_MIN);
  const bool stop = hit && next_T < float(SPLAT_T_MIN);
  s.done = s.done || stop;
  const float w = hit && !stop ? alpha * s.T : 0.0;
  s.accum = channels_fma(s.accum, w, color);
  s.depth_sum += w * depth;
  s.T = hit && !stop ? next_T : s.T;
  s.last = hit && !stop ? position : s.last;
  s.contributions += hit && !stop ? 1u : 0u;
}

// Whether every pixel of the subgroup has stopped.
bool all_done(PixelState s0, PixelState s1, PixelState s2, PixelState s3, PixelState s4, PixelState s5,
              PixelState s6, PixelState s7) {
  return subgroupAll(s0.done && s1.done && s2.done && s3.done && s4.done && s5.done && s6.done && s7.done);
}

// Writes the outputs, or the state the next pass continues from.
void finish_pixel(PixelState s, uint plane, bool final_pass) {
  if (!s.inside) return;
  const uint pix = s.pixel.y * view.width + s.pixel.x;
  for (uint c = 0u; c < CHANNELS; ++c) image[c * plane + pix] = s.accum[c];
  if (!final_pass) {  // more of the list follows in the next pass
    alpha_out[pix] = s.T;
    depth_out[pix] = s.depth_sum;
    last_out[pix] = s.last | (s.done ? FWD_LAST_DONE : 0u);
    return;
  }
  const float a = 1.0 - s.T;
  alpha_out[pix] = a;
  depth_out[pix] = a >= float(SPLAT_MIN_DEPTH_WEIGHT) ? s.depth_sum / a : 0.0;
  last_out[pix] = s.last;
}

void main() {
  const uvec2 base = block_origin();
  const uint tile = gl_WorkGroupID.y * view.tiles_x + gl_WorkGroupID.x;
  const uvec2 range = ranges[tile];
  const uint length = range.y - range.x;
  if (segment.begin >= length && segment.begin > 0u) return;  // the tile's list ended in an earlier pass
  const uint end = range.x + min(length, segment.end);
  const bool final_pass = length <= segment.end;
  const uint plane = view.width * view.height;
  PixelState s0 = start_pixel(base, plane);
  PixelState s1 = start_pixel(block_pixel(base, 1u, 0u), plane);
  PixelState s2 = start_pixel(block_pixel(base, 0u, 1u), plane);
  PixelState s3 = start_pixel(block_pixel(base, 1u, 1u), plane);
  PixelState s4 = start_pixel(block_pixel(base, 0u, 2u), plane);
  PixelState s5 = start_pixel(block_pixel(base, 1u, 2u), plane);
  PixelState s6 = start_pixel(block_pixel(base, 0u, 3u), plane);
  PixelState s7 = start_pixel(block_pixel(base, 1u, 3u), plane);
  const vec2 subgroup_lo = subgroupMin(s0.centre);
  const vec2 subgroup_hi = subgroupMax(PIXEL_BLOCK == 8u ? s7.centre : s0.centre);
  uint chunk = range.x + segment.begin;
  const uint lanes = subgroup_lanes();
  // do-while, not for: a CPU driver runs a loop's body once more, masked, when a for loop's test fails.
  if (chunk < end && !all_done(s0, s1, s2, s3, s4, s5, s6, s7)) do {
    const uint entry = chunk + gl_SubgroupInvocationID;
    vec4 mean_extent = vec4(0.0), conic_opacity = vec4(0.0), color = vec4(0.0);
    float depth = 0.0;
    bool relevant = false;
    if (entry < end) {
      uint g;
      float reach;  // for the ellipse test, which the forward does not take
      load_entry(entry, g, mean_extent, conic_opacity, depth, reach);
      // The bounding box only: the backward's exact ellipse test (footprint_touches_box) costs the forward
      // more than the cheap blends it skips (measured on lavapipe, docs/experiments.md).
      relevant = footprint_reaches(mean_extent, subgroup_lo, subgroup_hi);
      if (relevant) color = load_entry_color(g);
    }
    // A CPU driver runs an `if` masked and a loop's body at least once, so a `while` over the ballot's bits
    // would blend one empty entry more per word and chunk; this walk runs its body max(1, entries) times.
    const uvec4 ballot = subgroupBallot(relevant);
    for (uint word = 0u; word < ballot_words(); ++word) {
      uint todo = ballot[word];
      if (todo != 0u) do {
        const uint k = 32u * word + uint(findLSB(todo));
        todo &= todo - 1u;
        const vec4 me = subgroupShuffle(mean_extent, k);
        const vec4 co = subgroupShuffle(conic_opacity, k);
        const vec4 col = channels_shuffle(color, k);
        const float dep = subgroupShuffle(depth, k);
        const uint position = chunk + k - range.x + 1u;
        blend(s0, me, co, col, dep, position);
        if (PIXEL_BLOCK == 8u) {
          blend(s1, me, co, col, dep, position);
          blend(s2, me, co, col, dep, position);
          blend(s3, me, co, col, dep, position);
          blend(s4, me, co, col, dep, position);
          blend(s5, me, co, col, dep, position);
          blend(s6, me, co, col, dep, position);
          blend(s7, me, co, col, dep, position);
        }
      } while (todo != 0u);
    }
    chunk += lanes;
  } while (chunk < end && !all_done(s0, s1, s2, s3, s4, s5, s6, s7));
  // A driver's loop limit (lavapipe: 65535 iterations per invocation) ends the walk early without an error:
  // count it, so that a pass sized wrongly for a device is seen (SPLAT_COUNTER_FORWARD_WALKS_CUT).
  if (chunk < end && !all_done(s0, s1, s2, s3, s4, s5, s6, s7) && subgroupElect())
    atomicAdd(counters[SPLAT_COUNTER_FORWARD_WALKS_CUT], 1u);
  const uint subgroup_contributions = subgroupAdd(s0.contributions + s1.contributions + s2.contributions + s3.contributions + s4.contributions + s5.contributions + s6.contributions + s7.contributions);
  if (subgroupElect() && subgroup_contributions > 0u)
    atomicAdd(counters[SPLAT_COUNTER_CONTRIBUTIONS], subgroup_contributions);
  finish_pixel(s0, plane, final_pass);
  finish_pixel(s1, plane, final_pass);
  finish_pixel(s2, plane, final_pass);
  finish_pixel(s3, plane, final_pass);
  finish_pixel(s4, plane, final_pass);
  finish_pixel(s5, plane, final_pass);
  finish_pixel(s6, plane, final_pass);
  finish_pixel(s7, plane, final_pass);
}
