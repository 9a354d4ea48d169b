#version 450
#extension GL_GOOGLE_include_directive : require
// Per element: horizontal window sums of the three partial maps (first pass of the adjoint blur; with zero
// padding and a symmetric window the blur is its own adjoint).
#include "limits.h"
#include "elementwise.glsl"
#include "loss/loss_shared.h"
#include "loss/ssim_window.glsl"

layout(binding = SSIM_PARTIALS_BINDING_IN) uniform samplerBuffer partials;  // texels (loss_shared.h)
layout(std430, binding = SSIM_PARTIALS_BINDING_OUT) writeonly buffer Out { vec4 blurred[]; };
layout(push_constant) uniform Push { PhotometricParams p; };

void main() {
  const uint e = elementwise_index();
  if (e >= p.count) return;
  const int x = int(e % p.width);
  const int w = int(p.width);
  vec4 s = vec4(0.0);
#define TAP(k, wk) s += SSIM_TAP_WEIGHT(x, k, w, wk) * texelFetch(partials, int(e) + SSIM_TAP_OFFSET(x, k, w));
  SSIM_WINDOW(TAP)
#undef TAP
  blurred[e] = s;
}
