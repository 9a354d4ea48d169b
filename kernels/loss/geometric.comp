#version 450
#extension GL_GOOGLE_include_directive : require
// Per pixel: the LiDAR point-to-plane residual r = n . (P - D K^-1 [u + 0.5, v + 0.5, 1]), its loss rho(r)
// and dL/dD = -2 r (n . ray) / (1 + r^2 / s^2) / N_valid. Pixels without a valid point, or where nothing was
// rendered (D <= 0 or not finite), count 0 and get a zero gradient (see geometric_loss.h).
#include "limits.h"
#include "elementwise.glsl"
#include "loss/loss_shared.h"

layout(std430, binding = GEOMETRIC_BINDING_DEPTH) readonly buffer Depth { float depth[]; };
layout(std430, binding = GEOMETRIC_BINDING_PLANES) readonly buffer Planes { vec4 planes[]; };
layout(std430, binding = GEOMETRIC_BINDING_GRAD) writeonly buffer Grad { float grad[]; };
layout(std430, binding = GEOMETRIC_BINDING_TERMS) writeonly buffer Terms { vec2 terms[]; };
layout(push_constant) uniform Push { GeometricParams p; };

// Bitwise, so that fast-math cannot fold it away.
bool is_finite(float v) { return (floatBitsToUint(v) & 0x7F800000u) != 0x7F800000u; }

void main() {
  const uint i = elementwise_index();
  if (i >= p.count) return;
  const float d = depth[i];
  const vec4 plane = planes[i];
  const vec3 n = plane.xyz;
  float r2 = 0.0, g = 0.0, counted = 0.0;
  if (dot(n, n) > 0.25 && d > 0.0 && is_finite(d) && p.inv_valid > 0.0) {  // unit normal, or 0: no point
    const float u = float(i % p.width) + 0.5;
    const float v = float(i / p.width) + 0.5;
    const vec3 ray = vec3((u - p.cx) / p.fx, (v - p.cy) / p.fy, 1.0);
    const float n_ray = dot(n, ray);
    const float r = plane.w - d * n_ray;  // n . P - n . (D ray)
    // rho(r) = log(1 + r^2 / s^2) s^2 (Cauchy), r^2 when inv_scale2 = 0; its series where log(1 + x) in
    // float would lose the small x.
    const float x = r * r * p.inv_scale2;
    r2 = p.inv_scale2 == 0.0 ? r * r
                             : (x < 1e-3 ? r * r * (1.0 - x * (0.5 - x / 3.0)) : log(1.0 + x) / p.inv_scale2);
    g = p.weight * p.inv_valid * (-2.0 * r * n_ray) / (1.0 + x);
    counted = 1.0;
  }
  grad[i] = g;
  terms[i] = vec2(r2, counted);
}
