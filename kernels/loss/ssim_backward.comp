#version 450
#extension GL_GOOGLE_include_directive : require
// Per element: vertical window sums of the partials, then
//   dL/dx = G*A + 2 x (G*B) + y (G*C) + (1 - lambda) sign(x - y) / N,   written as weight * dL/dx.
#include "limits.h"
#include "elementwise.glsl"
#include "loss/loss_shared.h"
#include "loss/ssim_window.glsl"

layout(binding = SSIM_BACKWARD_BINDING_IMAGE) uniform samplerBuffer image;  // texels (loss_shared.h)
layout(binding = SSIM_BACKWARD_BINDING_TARGET) uniform samplerBuffer target;
layout(binding = SSIM_BACKWARD_BINDING_PARTIALS) uniform samplerBuffer partials;
layout(std430, binding = SSIM_BACKWARD_BINDING_GRAD) writeonly buffer Grad { float grad[]; };
layout(push_constant) uniform Push { PhotometricParams p; };

void main() {
  const uint e = elementwise_index();
  if (e >= p.count) return;
  const int y = int((e / p.width) % p.height);
  const int h = int(p.height);
  const int w = int(p.width);
  vec4 s = vec4(0.0);
#define TAP(k, wk) \
  s += SSIM_TAP_WEIGHT(y, k, h, wk) * texelFetch(partials, int(e) + SSIM_TAP_OFFSET(y, k, h) * w);
  SSIM_WINDOW(TAP)
#undef TAP
  const float xv = texelFetch(image, int(e)).x;
  const float yv = texelFetch(target, int(e)).x;
  const float l1 = (1.0 - p.lambda_ssim) * p.inv_count * sign(xv - yv);
  grad[e] = p.weight * (s.x + 2.0 * xv * s.y + yv * s.z + l1);
}
