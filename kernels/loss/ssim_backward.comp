#version 450
#extension GL_GOOGLE_include_directive : require
// Per element: vertical window sums of the partials, then
//   dL/dx = G*A + 2 x (G*B) + y (G*C) + (1 - lambda) sign(x - y) / N,   written as weight * dL/dx.
#include "limits.h"
#include "elementwise.glsl"
#include "loss/loss_shared.h"
#include "loss/ssim_window.glsl"

layout(std430, binding = SSIM_BACKWARD_BINDING_IMAGE) readonly buffer Image { float image[]; };
layout(std430, binding = SSIM_BACKWARD_BINDING_TARGET) readonly buffer Target { float target[]; };
layout(std430, binding = SSIM_BACKWARD_BINDING_PARTIALS) readonly buffer Partials { vec4 partials[]; };
layout(std430, binding = SSIM_BACKWARD_BINDING_GRAD) writeonly buffer Grad { float grad[]; };
layout(push_constant) uniform Push { PhotometricParams p; };

void main() {
  const uint e = elementwise_index();
  if (e >= p.count) return;
  const int y = int((e / p.width) % p.height);
  const int h = int(p.height);
  const int w = int(p.width);
  vec4 s = vec4(0.0);
#define TAP(k, wk) s += SSIM_TAP_WEIGHT(y, k, h, wk) * partials[int(e) + SSIM_TAP_OFFSET(y, k, h) * w];
  SSIM_WINDOW(TAP)
#undef TAP
  const float xv = image[e];
  const float yv = target[e];
  const float l1 = (1.0 - p.lambda_ssim) * p.inv_count * sign(xv - yv);
  grad[e] = p.weight * (s.x + 2.0 * xv * s.y + yv * s.z + l1);
}
