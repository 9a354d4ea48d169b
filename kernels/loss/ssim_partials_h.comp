#version 450
#extension GL_GOOGLE_include_directive : require
// Per element: horizontal window sums of the three partial maps (first pass of the adjoint blur; with zero
// padding and a symmetric window the blur is its own adjoint).
#include "limits.h"
#include "loss/loss_shared.h"
#include "loss/ssim_window.glsl"

layout(local_size_x = ELEMENTWISE_GROUP_SIZE) in;
layout(std430, binding = SSIM_PARTIALS_BINDING_IN) readonly buffer In { float partials[]; };
layout(std430, binding = SSIM_PARTIALS_BINDING_OUT) writeonly buffer Out { float blurred[]; };
layout(push_constant) uniform Push { PhotometricParams p; };

void main() {
  const uint e = gl_GlobalInvocationID.x;
  if (e >= p.count) return;
  const uint n = p.count;
  const int x = int(e % p.width);
  const int w = int(p.width);
  vec3 s = vec3(0.0);
#define TAP(k, wk)                                                        \
  if (x + (k) >= 0 && x + (k) < w) {                                      \
    const uint i = uint(int(e) + (k));                                    \
    s += float(wk) * vec3(partials[i], partials[n + i], partials[2u * n + i]); \
  }
  SSIM_WINDOW(TAP)
#undef TAP
  blurred[e] = s.x;
  blurred[n + e] = s.y;
  blurred[2u * n + e] = s.z;
}
