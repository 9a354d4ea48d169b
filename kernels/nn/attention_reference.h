// Double-precision CPU references of the attention operations LighterGlue runs (issue 47): the baseline
// each compute shader is tested against, tested itself through the whole matcher against an independent
// runtime (lighterglue_reference.h). Matrices are row-major, one row per keypoint.
#pragma once

#include <cstddef>
#include <vector>

#include "kernels/nn/nn_weights.h"

namespace litgs::kernels::nn {

struct Matrix {
  size_t rows = 0, cols = 0;
  std::vector<double> values;  // [row][col]
  Matrix() = default;
  Matrix(size_t r, size_t c) : rows(r), cols(c), values(r * c, 0.0) {}
  double& at(size_t r, size_t c) { return values[r * cols + c]; }
  double at(size_t r, size_t c) const { return values[r * cols + c]; }
};

// x W + b (ONNX MatMul then Add); std::invalid_argument when x's columns are not w.in.
Matrix linear(const Matrix& x, const LinearWeights& w);
// [a, b] along the columns (one row count).
Matrix concat_columns(const Matrix& a, const Matrix& b);
// a B^T scaled: out[i][j] = scale * sum_k a[i][k] b[j][k].
Matrix multiply_transposed(const Matrix& a, const Matrix& b, double scale);
// a b.
Matrix multiply(const Matrix& a, const Matrix& b);
Matrix add(const Matrix& a, const Matrix& b);
// Each row normalized to zero mean and unit variance (biased, + epsilon), then scaled and shifted.
void layer_norm(Matrix& x, const LayerNormWeights& w);
// The exact GELU: x (1 + erf(x / sqrt 2)) / 2.
void gelu(Matrix& x);
// Softmax of each row (the largest subtracted first).
void softmax_rows(Matrix& x);
// Log-softmax of each row, or of each column.
Matrix log_softmax_rows(const Matrix& x);
Matrix log_softmax_columns(const Matrix& x);
// LightGlue's rotary encoding of 2-D positions: the frequencies f = p W ([rows][dim/2]), each repeated for a
// pair of channels; x (d) cos f + rotate(x) (d) sin f, where rotate maps each pair (a, b) to (-b, a).
Matrix rotary_frequencies(const Matrix& positions, const std::vector<float>& w);
void apply_rotary(Matrix& x, const Matrix& frequencies);

}  // namespace litgs::kernels::nn
