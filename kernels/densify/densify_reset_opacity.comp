#version 450
#extension GL_GOOGLE_include_directive : require
// Per Gaussian: opacity = min(opacity, reset value), in logits (3DGS reset_opacity).
#include "limits.h"
#include "elementwise.glsl"
#include "densify/densify_shared.h"

layout(std430, binding = RESET_BINDING_OPACITY_LOGITS) buffer Logits { float opacity_logits[]; };
layout(push_constant) uniform Push { ResetOpacityParams p; };

void main() {
  const uint i = elementwise_index();
  if (i >= p.count) return;
  const float l = opacity_logits[i];
  if (l > p.max_logit) opacity_logits[i] = p.max_logit;
}
