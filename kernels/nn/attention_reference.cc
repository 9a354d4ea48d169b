#include "kernels/nn/attention_reference.h"

#include <algorithm>
#include <cmath>
#include <stdexcept>
#include <string>

namespace litgs::kernels::nn {
namespace {

void require(bool ok, const char* what) {
  if (!ok) throw std::invalid_argument(std::string("attention reference: ") + what);
}

}  // namespace

Matrix linear(const Matrix& x, const LinearWeights& w) {
  require(x.cols == w.in && w.weight.size() == size_t{w.in} * w.out, "linear: shapes differ");
  require(w.bias.empty() || w.bias.size() == w.out, "linear: bias size");
  Matrix y(x.rows, w.out);
  for (size_t r = 0; r < x.rows; ++r)
    for (size_t o = 0; o < w.out; ++o) {
      double s = w.bias.empty() ? 0.0 : w.bias[o];
      for (size_t i = 0; i < w.in; ++i) s += x.at(r, i) * w.weight[i * w.out + o];
      y.at(r, o) = s;
    }
  return y;
}

Matrix concat_columns(const Matrix& a, const Matrix& b) {
  require(a.rows == b.rows, "concat: row counts differ");
  Matrix y(a.rows, a.cols + b.cols);
  for (size_t r = 0; r < a.rows; ++r) {
    for (size_t c = 0; c < a.cols; ++c) y.at(r, c) = a.at(r, c);
    for (size_t c = 0; c < b.cols; ++c) y.at(r, a.cols + c) = b.at(r, c);
  }
  return y;
}

Matrix multiply_transposed(const Matrix& a, const Matrix& b, double scale) {
  require(a.cols == b.cols, "multiply_transposed: inner sizes differ");
  Matrix y(a.rows, b.rows);
  for (size_t i = 0; i < a.rows; ++i)
    for (size_t j = 0; j < b.rows; ++j) {
      double s = 0;
      for (size_t k = 0; k < a.cols; ++k) s += a.at(i, k) * b.at(j, k);
      y.at(i, j) = scale * s;
    }
  return y;
}

Matrix multiply(const Matrix& a, const Matrix& b) {
  require(a.cols == b.rows, "multiply: inner sizes differ");
  Matrix y(a.rows, b.cols);
  for (size_t i = 0; i < a.rows; ++i)
    for (size_t k = 0; k < a.cols; ++k)
      for (size_t j = 0; j < b.cols; ++j) y.at(i, j) += a.at(i, k) * b.at(k, j);
  return y;
}

Matrix add(const Matrix& a, const Matrix& b) {
  require(a.rows == b.rows && a.cols == b.cols, "add: shapes differ");
  Matrix y = a;
  for (size_t i = 0; i < y.values.size(); ++i) y.values[i] += b.values[i];
  return y;
}

void layer_norm(Matrix& x, const LayerNormWeights& w) {
  require(w.scale.size() == x.cols && w.bias.size() == x.cols, "layer_norm: sizes differ");
  for (size_t r = 0; r < x.rows; ++r) {
    double mean = 0, var = 0;
    for (size_t c = 0; c < x.cols; ++c) mean += x.at(r, c);
    mean /= double(x.cols);
    for (size_t c = 0; c < x.cols; ++c) var += (x.at(r, c) - mean) * (x.at(r, c) - mean);
    const double inv = 1.0 / std::sqrt(var / double(x.cols) + w.epsilon);
    for (size_t c = 0; c < x.cols; ++c) x.at(r, c) = (x.at(r, c) - mean) * inv * w.scale[c] + w.bias[c];
  }
}

void gelu(Matrix& x) {
  for (double& v : x.values) v = 0.5 * v * (1.0 + std::erf(v / std::sqrt(2.0)));
}

void softmax_rows(Matrix& x) {
  for (size_t r = 0; r < x.rows; ++r) {
    double top = -INFINITY, sum = 0;
    for (size_t c = 0; c < x.cols; ++c) top = std::max(top, x.at(r, c));
    for (size_t c = 0; c < x.cols; ++c) sum += (x.at(r, c) = std::exp(x.at(r, c) - top));
    for (size_t c = 0; c < x.cols; ++c) x.at(r, c) /= sum;
  }
}

Matrix log_softmax_rows(const Matrix& x) {
  Matrix y = x;
  for (size_t r = 0; r < x.rows; ++r) {
    double top = -INFINITY, sum = 0;
    for (size_t c = 0; c < x.cols; ++c) top = std::max(top, x.at(r, c));
    for (size_t c = 0; c < x.cols; ++c) sum += std::exp(x.at(r, c) - top);
    const double log_sum = top + std::log(sum);
    for (size_t c = 0; c < x.cols; ++c) y.at(r, c) = x.at(r, c) - log_sum;
  }
  return y;
}

Matrix log_softmax_columns(const Matrix& x) {
  Matrix t(x.cols, x.rows), y(x.rows, x.cols);
  for (size_t r = 0; r < x.rows; ++r)
    for (size_t c = 0; c < x.cols; ++c) t.at(c, r) = x.at(r, c);
  const Matrix lt = log_softmax_rows(t);
  for (size_t r = 0; r < x.rows; ++r)
    for (size_t c = 0; c < x.cols; ++c) y.at(r, c) = lt.at(c, r);
  return y;
}

Matrix rotary_frequencies(const Matrix& positions, const std::vector<float>& w) {
  require(positions.cols == 2 && w.size() % 2 == 0, "rotary_frequencies: 2-D positions, [2][half] weights");
  const size_t half = w.size() / 2;
  Matrix f(positions.rows, half);
  for (size_t r = 0; r < positions.rows; ++r)
    for (size_t k = 0; k < half; ++k)
      f.at(r, k) = positions.at(r, 0) * w[k] + positions.at(r, 1) * w[half + k];
  return f;
}

void apply_rotary(Matrix& x, const Matrix& f) {
  require(x.rows == f.rows && x.cols == 2 * f.cols, "apply_rotary: shapes differ");
  for (size_t r = 0; r < x.rows; ++r)
    for (size_t k = 0; k < f.cols; ++k) {
      const double a = x.at(r, 2 * k), b = x.at(r, 2 * k + 1);
      const double c = std::cos(f.at(r, k)), s = std::sin(f.at(r, k));
      x.at(r, 2 * k) = a * c - b * s;
      x.at(r, 2 * k + 1) = b * c + a * s;
    }
}

}  // namespace litgs::kernels::nn
