// The inputs of tests/data/lighterglue/make_reference.js, computed by the same formulas (float32 values, as
// the script feeds them): image 1's keypoints and descriptors are image 0's shuffled, moved and perturbed,
// plus 8 of its own.
#pragma once

#include <cmath>

#include "kernels/nn/attention_reference.h"

namespace litgs::testing::lighterglue_inputs {

constexpr int kN0 = 40, kN1 = 48, kDescriptor = 64;

inline double keypoint0(int i, int c) {
  const double t = 0.37 * i, r = 0.9 * (0.2 + 0.8 * double((i * 7) % kN0) / kN0);
  return c == 0 ? r * std::cos(t) : r * std::sin(t) * 0.8;
}
inline int source(int j) {
  return (j * 13) % kN0;
}
inline double keypoint1(int j, int c) {
  if (j < kN0) return keypoint0(source(j), c) + (c == 0 ? 0.05 : -0.03);
  return c == 0 ? -0.8 + 0.2 * (j - kN0) : 0.7 - 0.15 * (j - kN0);
}
inline double descriptor0(int i, int d) {
  return std::sin(1.3 * i + 0.71 * d + 0.05 * i * d) + 0.3 * std::cos(2.1 * d - i);
}
inline double descriptor1(int j, int d) {
  if (j < kN0) return descriptor0(source(j), d) + 0.25 * std::sin(5.1 * j + 1.7 * d);
  return std::cos(0.9 * j + 1.9 * d) + 0.2 * std::sin(d * j);
}

template <class F>
kernels::nn::Matrix rows(int n, int cols, F f, bool normalize) {
  kernels::nn::Matrix m(n, cols);
  for (int i = 0; i < n; ++i) {
    double norm = 0;
    for (int c = 0; c < cols; ++c) norm += f(i, c) * f(i, c);
    norm = normalize ? std::sqrt(norm) : 1.0;
    for (int c = 0; c < cols; ++c) m.at(i, c) = double(float(f(i, c) / norm));
  }
  return m;
}

inline kernels::nn::Matrix keypoints0() {
  return rows(kN0, 2, keypoint0, false);
}
inline kernels::nn::Matrix keypoints1() {
  return rows(kN1, 2, keypoint1, false);
}
inline kernels::nn::Matrix descriptors0() {
  return rows(kN0, kDescriptor, descriptor0, true);
}
inline kernels::nn::Matrix descriptors1() {
  return rows(kN1, kDescriptor, descriptor1, true);
}

}  // namespace litgs::testing::lighterglue_inputs
