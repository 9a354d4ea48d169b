#version 450
#extension GL_GOOGLE_include_directive : require
#extension GL_KHR_shader_subgroup_vote : require
// One workgroup per 16x16 tile, one invocation per pixel: alpha-blend the tile's list front to back.
// Every lane reads the same list entry at a time (uniform loads, no shared memory, no barriers: cheap on
// CPU drivers, cached on GPUs). A subgroup leaves the loop when all its pixels are done.
#include "limits.h"
#include "splat/splat_shared.h"
#include "splat/splat_math.h"
#include "splat/splat_view.glsl"

layout(local_size_x = SPLAT_TILE_SIZE, local_size_y = SPLAT_TILE_SIZE) in;

layout(std430, binding = FWD_BINDING_RANGES) readonly buffer Ranges { uvec2 ranges[]; };
layout(std430, binding = FWD_BINDING_ISECT_IDS) readonly buffer IsectIds { uint isect_ids[]; };
layout(std430, binding = FWD_BINDING_ISECT_GAUSSIAN) readonly buffer IsectGaussian { uint isect_gaussian[]; };
layout(std430, binding = FWD_BINDING_MEANS2D) readonly buffer Means2d { float means2d[]; };
layout(std430, binding = FWD_BINDING_CONICS) readonly buffer Conics { float conics[]; };
layout(std430, binding = FWD_BINDING_DEPTHS) readonly buffer Depths { float depths[]; };
layout(std430, binding = FWD_BINDING_OPACITIES) readonly buffer Opacities { float opacities[]; };
layout(std430, binding = FWD_BINDING_COLORS) readonly buffer Colors { float colors[]; };
layout(std430, binding = FWD_BINDING_IMAGE) writeonly buffer Image { float image[]; };
layout(std430, binding = FWD_BINDING_DEPTH) writeonly buffer Depth { float depth_out[]; };
layout(std430, binding = FWD_BINDING_ALPHA) writeonly buffer Alpha { float alpha_out[]; };
layout(std430, binding = FWD_BINDING_LAST) writeonly buffer Last { uint last_out[]; };
layout(std430, binding = FWD_BINDING_COUNTERS) buffer Counters { uint counters[]; };

void main() {
  const uvec2 pixel = gl_GlobalInvocationID.xy;
  const bool inside = pixel.x < view.width && pixel.y < view.height;
  const uint tile = gl_WorkGroupID.y * view.tiles_x + gl_WorkGroupID.x;
  const uvec2 range = ranges[tile];
  const uint end = min(range.y, range.x + uint(MAX_TILE_LIST_WALK));
  if (gl_LocalInvocationIndex == 0u && end < range.y) atomicAdd(counters[1], 1u);

  const vec2 centre = vec2(pixel) + 0.5;
  float T = 1.0;
  float accum[SPLAT_MAX_CHANNELS] = float[SPLAT_MAX_CHANNELS](0.0, 0.0, 0.0, 0.0);
  float depth_sum = 0.0;
  uint last = 0u;
  bool done = !inside;
  for (uint i = range.x; i < end; ++i) {
    if (subgroupAll(done)) break;
    const uint g = isect_gaussian[isect_ids[i]];
    if (done) continue;
    const vec3 conic = vec3(conics[3 * g], conics[3 * g + 1], conics[3 * g + 2]);
    const vec2 d = centre - vec2(means2d[2 * g], means2d[2 * g + 1]);
    const float sigma = gaussian_sigma(conic, d);
    if (sigma < 0.0) continue;
    const float alpha = min(float(SPLAT_ALPHA_MAX), opacities[g] * exp(-sigma));
    if (alpha < float(SPLAT_ALPHA_MIN)) continue;
    const float next_T = T * (1.0 - alpha);
    if (next_T < float(SPLAT_T_MIN)) {
      done = true;
      continue;
    }
    const float w = alpha * T;
    for (uint c = 0u; c < CHANNELS; ++c) accum[c] += w * colors[g * CHANNELS + c];
    depth_sum += w * depths[g];
    T = next_T;
    last = i - range.x + 1u;
  }
  if (!inside) return;
  const uint pix = pixel.y * view.width + pixel.x;
  const uint plane = view.width * view.height;
  for (uint c = 0u; c < CHANNELS; ++c) image[c * plane + pix] = accum[c];
  const float a = 1.0 - T;
  alpha_out[pix] = a;
  depth_out[pix] = a >= float(SPLAT_MIN_DEPTH_WEIGHT) ? depth_sum / a : 0.0;
  last_out[pix] = last;
}
