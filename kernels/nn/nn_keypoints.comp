#version 450
#extension GL_GOOGLE_include_directive : require
// XFeat's post-processing, each op as kernels/nn/xfeat_keypoints_reference.cc computes it: the keypoint
// heat map (softmax, 8 x 8 cells to pixels), NMS scores times reliability, channel normalization and the
// descriptors at the keypoints (bicubic, L2-normalized).
#include "limits.h"
#include "nn/nn_shared.h"
#include "elementwise.glsl"

layout(std430, binding = NN_KEYPOINTS_BINDING_A) readonly buffer A { float a[]; };
layout(std430, binding = NN_KEYPOINTS_BINDING_B) readonly buffer B { float b[]; };
layout(std430, binding = NN_KEYPOINTS_BINDING_OUT) writeonly buffer Out { float y[]; };
layout(push_constant) uniform Push { NnKeypointsParams p; };

// a as a [channels][map_height][map_width] map, zero outside.
float map_tap(uint c, int row, int column) {
  if (row < 0 || column < 0 || row >= int(p.map_height) || column >= int(p.map_width)) return 0.0;
  return a[(c * p.map_height + uint(row)) * p.map_width + uint(column)];
}

float map_coordinate(float full, uint map_size, uint full_size) {
  return full * float(map_size) / float(max(full_size, 2u) - 1u) - 0.5;
}

// One cell: its softmax's maximum and sum once, then its 64 pixels.
void heatmap(uint cell) {
  const uint plane = p.map_height * p.map_width;
  const uint X0 = (cell % p.map_width) * 8u, Y0 = (cell / p.map_width) * 8u;
  float top = a[cell];
  for (uint k = 1u; k < 65u; ++k) top = max(top, a[k * plane + cell]);
  float sum = 0.0;
  for (uint k = 0u; k < 65u; ++k) sum += exp(a[k * plane + cell] - top);
  for (uint k = 0u; k < 64u; ++k)
    y[(Y0 + k / 8u) * p.width + X0 + k % 8u] = exp(a[k * plane + cell] - top) / sum;
}

// b as the [map_height][map_width] reliability, bilinear at a full-resolution pixel, zero outside.
float reliability_tap(int row, int column) {
  if (row < 0 || column < 0 || row >= int(p.map_height) || column >= int(p.map_width)) return 0.0;
  return b[uint(row) * p.map_width + uint(column)];
}

void scores(uint e) {
  const int X = int(e % p.width), Y = int(e / p.width);
  const float h = a[e];
  y[e] = 0.0;
  if (!(h > p.threshold)) return;
  const int r = int(p.window / 2u);
  for (int dy = -r; dy <= r; ++dy)
    for (int dx = -r; dx <= r; ++dx) {
      const int yy = Y + dy, xx = X + dx;
      if (yy >= 0 && xx >= 0 && yy < int(p.height) && xx < int(p.width) && a[uint(yy) * p.width + uint(xx)] > h)
        return;
    }
  const float u = map_coordinate(float(X), p.map_width, p.width);
  const float v = map_coordinate(float(Y), p.map_height, p.height);
  const int x0 = int(floor(u)), y0 = int(floor(v));
  const float tx = u - float(x0), ty = v - float(y0);
  const float rel = (1.0 - ty) * ((1.0 - tx) * reliability_tap(y0, x0) + tx * reliability_tap(y0, x0 + 1)) +
                    ty * ((1.0 - tx) * reliability_tap(y0 + 1, x0) + tx * reliability_tap(y0 + 1, x0 + 1));
  y[e] = h * rel;
}

// One pixel: its norm over the channels once, then each channel.
void normalize_channels(uint pixel) {
  const uint plane = p.map_height * p.map_width;
  float sq = 0.0;
  for (uint c = 0u; c < p.channels; ++c) sq += a[c * plane + pixel] * a[c * plane + pixel];
  const float n = max(sqrt(sq), 1e-12);
  for (uint c = 0u; c < p.channels; ++c) y[c * plane + pixel] = a[c * plane + pixel] / n;
}

// Keys' cubic convolution, a = -0.75, taps at -1, 0, 1, 2 from floor.
vec4 cubic_weights(float t) {
  const float A = -0.75;
  const float d0 = t + 1.0, d3 = 2.0 - t, s = 1.0 - t;
  return vec4(((A * d0 - 5.0 * A) * d0 + 8.0 * A) * d0 - 4.0 * A, ((A + 2.0) * t - (A + 3.0)) * t * t + 1.0,
              ((A + 2.0) * s - (A + 3.0)) * s * s + 1.0, ((A * d3 - 5.0 * A) * d3 + 8.0 * A) * d3 - 4.0 * A);
}

void descriptor(uint k) {
  const float u = map_coordinate(b[2u * k], p.map_width, p.width);
  const float v = map_coordinate(b[2u * k + 1u], p.map_height, p.height);
  const int x0 = int(floor(u)), y0 = int(floor(v));
  const vec4 wx = cubic_weights(u - float(x0)), wy = cubic_weights(v - float(y0));
  float d[NN_KEYPOINTS_MAX_CHANNELS];
  float sq = 0.0;
  for (uint c = 0u; c < p.channels; ++c) {
    float s = 0.0;
    for (int j = 0; j < 4; ++j)
      for (int i = 0; i < 4; ++i) s += wy[j] * wx[i] * map_tap(c, y0 - 1 + j, x0 - 1 + i);
    d[c] = s;
    sq += s * s;
  }
  const float n = max(sqrt(sq), 1e-12);
  for (uint c = 0u; c < p.channels; ++c) y[k * p.channels + c] = d[c] / n;
}

void main() {
  const uint e = elementwise_index();
  if (e >= p.count) return;
  if (p.op == NN_KEYPOINTS_HEATMAP)
    heatmap(e);
  else if (p.op == NN_KEYPOINTS_SCORES)
    scores(e);
  else if (p.op == NN_KEYPOINTS_NORMALIZE)
    normalize_channels(e);
  else
    descriptor(e);
}
