#version 450
#extension GL_GOOGLE_include_directive : require
// Per element: vertical window sums of the five moment rows (mu_x, mu_y, E[x^2], E[y^2], E[xy]), SSIM,
// and the loss's partials w.r.t. (mu_x, E[x^2], E[xy]) for the backward; the per-element loss terms.
#include "limits.h"
#include "elementwise.glsl"
#include "loss/loss_shared.h"
#include "loss/ssim_window.glsl"

layout(binding = SSIM_PIXEL_BINDING_IMAGE) uniform samplerBuffer image;  // texels (loss_shared.h)
layout(binding = SSIM_PIXEL_BINDING_TARGET) uniform samplerBuffer target;
layout(binding = SSIM_PIXEL_BINDING_MOMENTS4) uniform samplerBuffer moments4;
layout(binding = SSIM_PIXEL_BINDING_MOMENTS1) uniform samplerBuffer moments1;
layout(std430, binding = SSIM_PIXEL_BINDING_PARTIALS) writeonly buffer Partials { vec4 partials[]; };
layout(std430, binding = SSIM_PIXEL_BINDING_TERMS) writeonly buffer Terms { vec2 terms[]; };
layout(push_constant) uniform Push { PhotometricParams p; };

void main() {
  const uint e = elementwise_index();
  if (e >= p.count) return;
  const int y = int((e / p.width) % p.height);
  const int h = int(p.height);
  const int w = int(p.width);
  vec4 m = vec4(0.0);  // mu_x, mu_y, E[x^2], E[y^2]
  float exy = 0.0;
#define TAP(k, wk)                                           \
  {                                                          \
    const int i = int(e) + SSIM_TAP_OFFSET(y, k, h) * w;     \
    const float wt = SSIM_TAP_WEIGHT(y, k, h, wk);           \
    m += wt * texelFetch(moments4, i);                       \
    exy += wt * texelFetch(moments1, i).x;                   \
  }
  SSIM_WINDOW(TAP)
#undef TAP
  const float mux = m.x, muy = m.y;
  const float sxx = m.z - mux * mux;
  const float syy = m.w - muy * muy;
  const float sxy = exy - mux * muy;
  const float a1 = 2.0 * mux * muy + float(SSIM_C1);
  const float a2 = 2.0 * sxy + float(SSIM_C2);
  const float b1 = mux * mux + muy * muy + float(SSIM_C1);
  const float b2 = sxx + syy + float(SSIM_C2);
  const float inv_b = 1.0 / (b1 * b2);
  const float ssim = a1 * a2 * inv_b;
  // dS/dmu_x, dS/dE[x^2], dS/dE[xy] (sigma terms depend on the means too), times dL/dS = -lambda / N.
  const float d_mux = 2.0 * (muy * (a2 - a1) - mux * ssim * (b2 - b1)) * inv_b;
  const float d_ex2 = -ssim / b2;
  const float d_exy = 2.0 * a1 * inv_b;
  const float g = -p.lambda_ssim * p.inv_count;
  partials[e] = vec4(g * d_mux, g * d_ex2, g * d_exy, 0.0);
  terms[e] = vec2(1.0 - ssim, abs(texelFetch(image, int(e)).x - texelFetch(target, int(e)).x));
}
