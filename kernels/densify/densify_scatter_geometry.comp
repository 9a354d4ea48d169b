#version 450
#extension GL_GOOGLE_include_directive : require
// Per Gaussian: means and log-scales at the scanned offset. Split children are sampled from the parent
// (3DGS densify_and_split): mean + R diag(scale) z, z a standard normal per axis truncated at 3 (so a
// child lies within the parent's 3 sigma along each principal axis), log-scales - log(1.6).
#include "limits.h"
#include "elementwise.glsl"
#include "splat/splat_shared.h"
#include "splat/splat_math.h"
#include "densify/densify_shared.h"
#include "densify/densify_math.h"

layout(std430, binding = GEOMETRY_BINDING_DECISION) readonly buffer Decision { uint decision[]; };
layout(std430, binding = GEOMETRY_BINDING_OFFSETS) readonly buffer Offsets { uint offsets[]; };
layout(std430, binding = GEOMETRY_BINDING_MEANS) readonly buffer Means { float means[]; };
layout(std430, binding = GEOMETRY_BINDING_LOG_SCALES) readonly buffer LogScales { float log_scales[]; };
layout(std430, binding = GEOMETRY_BINDING_QUATS) readonly buffer Quats { float quats[]; };
layout(std430, binding = GEOMETRY_BINDING_MEANS_OUT) writeonly buffer MeansOut { float means_out[]; };
layout(std430, binding = GEOMETRY_BINDING_LOG_SCALES_OUT) writeonly buffer LogScalesOut {
  float log_scales_out[];
};
layout(push_constant) uniform Push { ScatterParams p; };

const float TWO_PI = 6.283185307179586;

float split_normal(uint i, uint child, uint axis) {
  const float u1 = split_uniform(p.seed, p.step, i, child, axis, 0u);
  const float u2 = split_uniform(p.seed, p.step, i, child, axis, 1u);
  return clamp(sqrt(-2.0 * log(u1)) * cos(TWO_PI * u2), -3.0, 3.0);
}

void write_child(uint i, uint to, uint child, bool split, vec3 mean, vec3 log_scale, mat3 R) {
  vec3 m = mean;
  vec3 s = log_scale;
  if (split) {
    const vec3 z = vec3(split_normal(i, child, 0u), split_normal(i, child, 1u), split_normal(i, child, 2u));
    m = mean + R * (exp(log_scale) * z);
    s = log_scale - vec3(p.log_split_divisor);
  }
  means_out[3 * to] = m.x;
  means_out[3 * to + 1] = m.y;
  means_out[3 * to + 2] = m.z;
  log_scales_out[3 * to] = s.x;
  log_scales_out[3 * to + 1] = s.y;
  log_scales_out[3 * to + 2] = s.z;
}

void main() {
  const uint i = elementwise_index();
  if (i >= p.count) return;
  const uint d = decision[i];
  const bool a = (d & DENSIFY_SLOT_A) != 0u;
  const bool b = (d & DENSIFY_SLOT_B) != 0u;
  if (!a && !b) return;
  const bool split = (d & DENSIFY_KIND_MASK) == DENSIFY_KIND_SPLIT;
  const vec3 mean = vec3(means[3 * i], means[3 * i + 1], means[3 * i + 2]);
  const vec3 log_scale = vec3(log_scales[3 * i], log_scales[3 * i + 1], log_scales[3 * i + 2]);
  mat3 R = mat3(1.0);
  if (split)
    R = rotation_from_unit_quat(
        unit_quat(vec4(quats[4 * i], quats[4 * i + 1], quats[4 * i + 2], quats[4 * i + 3])));
  const uint o = offsets[i];
  if (a) write_child(i, o, 0u, split, mean, log_scale, R);
  if (b) write_child(i, a ? o + 1u : o, 1u, split, mean, log_scale, R);
}
