#version 450
#extension GL_GOOGLE_include_directive : require
// Per Gaussian, after a backward: accumulate the densification statistics of visible Gaussians (3DGS
// add_densification_stats; visible = the rasterizer's tile rectangle is not empty, as 3DGS's radii > 0).
#include "limits.h"
#include "elementwise.glsl"
#include "splat/splat_shared.h"
#include "splat/splat_math.h"
#include "splat/splat_view.glsl"
#include "densify/densify_shared.h"

layout(std430, binding = STATS_BINDING_MEANS) readonly buffer Means { float means[]; };
layout(std430, binding = STATS_BINDING_LOG_SCALES) readonly buffer LogScales { float log_scales[]; };
layout(std430, binding = STATS_BINDING_QUATS) readonly buffer Quats { float quats[]; };
layout(std430, binding = STATS_BINDING_OPACITY_LOGITS) readonly buffer Logits { float opacity_logits[]; };
layout(std430, binding = STATS_BINDING_TILE_RECTS) readonly buffer Rects { uvec2 rects[]; };
#include "splat/tile_rect.glsl"
layout(std430, binding = STATS_BINDING_GRAD2D) readonly buffer Grad2d { float grad2d[]; };
layout(std430, binding = STATS_BINDING_GRAD_ACCUM) buffer GradAccum { float grad_accum[]; };
layout(std430, binding = STATS_BINDING_DENOM) buffer Denom { uint denom[]; };
layout(std430, binding = STATS_BINDING_MAX_RADIUS) buffer MaxRadius { float max_radius[]; };

void main() {
  const uint i = elementwise_index();
  if (i >= view.count) return;
  const uvec4 rect = unpack_tile_rect(rects[i]);
  if (rect.z <= rect.x || rect.w <= rect.y) return;
  // 3DGS's viewspace gradient is w.r.t. NDC (its backward multiplies dL/dpixel by W/2 and H/2): the same
  // scaling here makes its threshold (0.0002) apply unchanged, independent of the image size.
  const vec2 g = vec2(grad2d[i * GRAD2D_STRIDE] * (0.5 * float(view.width)),
                      grad2d[i * GRAD2D_STRIDE + 1] * (0.5 * float(view.height)));
  const float norm = length(g);
  if (is_finite_real(norm)) grad_accum[i] += norm;
  denom[i] += 1u;
  // The screen radius: the rasterizer's opacity-aware extent (where alpha falls to 1/255), recomputed with
  // the same function so it agrees with the tile rectangle.
  const vec3 mean = vec3(means[3 * i], means[3 * i + 1], means[3 * i + 2]);
  const vec3 log_scale = vec3(log_scales[3 * i], log_scales[3 * i + 1], log_scales[3 * i + 2]);
  const vec4 quat = vec4(quats[4 * i], quats[4 * i + 1], quats[4 * i + 2], quats[4 * i + 3]);
  const Projected pr = project_gaussian(view_geometry(), mean, log_scale, quat, opacity_logits[i]);
  const float radius = max(pr.extent.x, pr.extent.y);
  if (is_finite_real(radius) && radius > max_radius[i]) max_radius[i] = radius;
}
