#version 450
#extension GL_GOOGLE_include_directive : require
// Per element: horizontal window sums of x, y, x^2, y^2 and xy (the first pass of the separable blur).
#include "limits.h"
#include "loss/loss_shared.h"
#include "loss/ssim_window.glsl"

layout(local_size_x = ELEMENTWISE_GROUP_SIZE) in;
layout(std430, binding = SSIM_MOMENTS_BINDING_IMAGE) readonly buffer Image { float image[]; };
layout(std430, binding = SSIM_MOMENTS_BINDING_TARGET) readonly buffer Target { float target[]; };
layout(std430, binding = SSIM_MOMENTS_BINDING_OUT) writeonly buffer Moments { float moments[]; };
layout(push_constant) uniform Push { PhotometricParams p; };

void main() {
  const uint e = gl_GlobalInvocationID.x;
  if (e >= p.count) return;
  const int x = int(e % p.width);
  const int w = int(p.width);
  vec4 m = vec4(0.0);  // x, y, x^2, y^2
  float mxy = 0.0;
#define TAP(k, wk)                                       \
  if (x + (k) >= 0 && x + (k) < w) {                     \
    const float a = image[int(e) + (k)];                 \
    const float b = target[int(e) + (k)];                \
    m += float(wk) * vec4(a, b, a * a, b * b);           \
    mxy += float(wk) * (a * b);                          \
  }
  SSIM_WINDOW(TAP)
#undef TAP
  moments[e] = m.x;
  moments[p.count + e] = m.y;
  moments[2u * p.count + e] = m.z;
  moments[3u * p.count + e] = m.w;
  moments[4u * p.count + e] = mxy;
}
