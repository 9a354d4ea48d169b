#version 450
#extension GL_GOOGLE_include_directive : require
// Per element: horizontal window sums of x, y, x^2, y^2 and xy (the first pass of the separable blur).
#include "limits.h"
#include "elementwise.glsl"
#include "loss/loss_shared.h"
#include "loss/ssim_window.glsl"

layout(binding = SSIM_MOMENTS_BINDING_IMAGE) uniform samplerBuffer image;    // texels (loss_shared.h)
layout(binding = SSIM_MOMENTS_BINDING_TARGET) uniform samplerBuffer target;
layout(std430, binding = SSIM_MOMENTS_BINDING_OUT4) writeonly buffer Moments4 { vec4 moments4[]; };
layout(std430, binding = SSIM_MOMENTS_BINDING_OUT1) writeonly buffer Moments1 { float moments1[]; };
layout(push_constant) uniform Push { PhotometricParams p; };

void main() {
  const uint e = elementwise_index();
  if (e >= p.count) return;
  const int x = int(e % p.width);
  const int w = int(p.width);
  vec4 m = vec4(0.0);  // x, y, x^2, y^2
  float mxy = 0.0;
#define TAP(k, wk)                                       \
  {                                                      \
    const int i = int(e) + SSIM_TAP_OFFSET(x, k, w);     \
    const float wt = SSIM_TAP_WEIGHT(x, k, w, wk);       \
    const float a = texelFetch(image, i).x;              \
    const float b = texelFetch(target, i).x;             \
    m += wt * vec4(a, b, a * a, b * b);                  \
    mxy += wt * (a * b);                                 \
  }
  SSIM_WINDOW(TAP)
#undef TAP
  moments4[e] = m;
  moments1[e] = mxy;
}
