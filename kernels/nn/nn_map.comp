#version 450
#extension GL_GOOGLE_include_directive : require
// The feature-map operations of a network besides convolution, one output element per invocation, each as
// kernels/nn/nn_reference.cc computes it: add, average pool, bilinear resize (half-pixel), unfold, and the
// add of a resized map.
#include "limits.h"
#include "nn/nn_shared.h"
#include "elementwise.glsl"

// The operands are uniform texel buffers, as the convolution's input (nn_conv2d.comp): on CPU drivers a texel
// fetch at a per-lane index is one vector gather, a storage-buffer load a loop over the lanes.
layout(binding = NN_MAP_BINDING_A) uniform samplerBuffer a;
layout(binding = NN_MAP_BINDING_B) uniform samplerBuffer b;
layout(std430, binding = NN_MAP_BINDING_OUT) writeonly buffer Out { float y[]; };
layout(push_constant) uniform Push { NnMapParams p; };

float at(uint c, uint row, uint column) {
  return texelFetch(a, int((c * p.in_height + row) * p.in_width + column)).x;
}

// Source coordinate of output index d along a side of in_size -> out_size samples.
void source(uint d, uint in_size, uint out_size, out uint i0, out uint i1, out float t) {
  float s = (float(d) + 0.5) * float(in_size) / float(out_size) - 0.5;
  s = clamp(s, 0.0, float(in_size - 1u));
  i0 = uint(floor(s));
  i1 = min(i0 + 1u, in_size - 1u);
  t = s - float(i0);
}

// Channel c of a resized bilinearly to the output's size, at the output's (row, x).
float resized(uint c, uint row, uint x) {
  uint y0, y1, x0, x1;
  float ty, tx;
  source(row, p.in_height, p.out_height, y0, y1, ty);
  source(x, p.in_width, p.out_width, x0, x1, tx);
  return (1.0 - ty) * ((1.0 - tx) * at(c, y0, x0) + tx * at(c, y0, x1)) +
         ty * ((1.0 - tx) * at(c, y1, x0) + tx * at(c, y1, x1));
}

void main() {
  const uint e = elementwise_index();
  if (e >= p.count) return;
  if (p.op == NN_MAP_ADD) {
    y[e] = texelFetch(a, int(e)).x + texelFetch(b, int(e)).x;
    return;
  }
  const uint x = e % p.out_width;
  const uint row = (e / p.out_width) % p.out_height;
  const uint c = e / (p.out_width * p.out_height);
  if (p.op == NN_MAP_AVERAGE_POOL) {
    float sum = 0.0;
    for (uint ky = 0u; ky < p.k; ++ky)
      for (uint kx = 0u; kx < p.k; ++kx) sum += at(c, row * p.k + ky, x * p.k + kx);
    y[e] = sum / float(p.k * p.k);
  } else if (p.op == NN_MAP_RESIZE) {
    y[e] = resized(c, row, x);
  } else if (p.op == NN_MAP_ADD_RESIZED) {
    // A feature pyramid's upsample-and-add in one pass: the resized map is never written.
    y[e] = texelFetch(b, int(e)).x + resized(c, row, x);
  } else {  // NN_MAP_UNFOLD
    const uint ky = c / p.k, kx = c % p.k;
    y[e] = at(0u, row * p.k + ky, x * p.k + kx);
  }
}
