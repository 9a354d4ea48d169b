#include "kernels/nn/lighterglue_reference.h"

#include <algorithm>
#include <cmath>
#include <stdexcept>

namespace litgs::kernels::nn {
namespace {

// The feed-forward update: x + project(gelu(norm(expand([x, message])))).
Matrix update(const Matrix& x, const Matrix& message, const FeedForwardWeights& f) {
  Matrix h = linear(concat_columns(x, message), f.expand);
  layer_norm(h, f.norm);
  gelu(h);
  return add(x, linear(h, f.project));
}

// Self-attention with rotary encoding, one head: q, k, v are channels 3 d + 0, 1, 2 of the projection.
Matrix self_block(const Matrix& x, const Matrix& frequencies, const LighterGlueWeights::Layer& L) {
  const Matrix qkv = linear(x, L.qkv);
  const size_t dim = x.cols;
  Matrix q(x.rows, dim), k(x.rows, dim), v(x.rows, dim);
  for (size_t r = 0; r < x.rows; ++r)
    for (size_t d = 0; d < dim; ++d) {
      q.at(r, d) = qkv.at(r, 3 * d);
      k.at(r, d) = qkv.at(r, 3 * d + 1);
      v.at(r, d) = qkv.at(r, 3 * d + 2);
    }
  apply_rotary(q, frequencies);
  apply_rotary(k, frequencies);
  Matrix attention = multiply_transposed(q, k, 1.0 / std::sqrt(double(dim)));
  softmax_rows(attention);
  return update(x, linear(multiply(attention, v), L.self_out), L.self_ffn);
}

}  // namespace

Matrix normalize_keypoints(const std::vector<float>& xy, int width, int height) {
  if (xy.size() % 2 || width <= 0 || height <= 0)
    throw std::invalid_argument("normalize_keypoints: (x, y) pairs and a positive image size");
  const double scale = std::max(width, height) / 2.0;
  Matrix m(xy.size() / 2, 2);
  for (size_t i = 0; i < m.rows; ++i) {
    m.at(i, 0) = (xy[2 * i] - width / 2.0) / scale;
    m.at(i, 1) = (xy[2 * i + 1] - height / 2.0) / scale;
  }
  return m;
}

void mutual_best(const Matrix& s, std::vector<std::array<int, 2>>& matches, std::vector<double>& values) {
  matches.clear();
  values.clear();
  std::vector<size_t> best_row(s.cols, 0);  // per column, its best row
  for (size_t j = 0; j < s.cols; ++j)
    for (size_t i = 1; i < s.rows; ++i)
      if (s.at(i, j) > s.at(best_row[j], j)) best_row[j] = i;
  for (size_t i = 0; i < s.rows && s.cols; ++i) {
    size_t best = 0;
    for (size_t j = 1; j < s.cols; ++j)
      if (s.at(i, j) > s.at(i, best)) best = j;
    if (best_row[best] != i) continue;
    matches.push_back({int(i), int(best)});
    values.push_back(std::exp(s.at(i, best)));
  }
}

LighterGlueOutputs lighterglue(const LighterGlueWeights& w, const Matrix& kp0, const Matrix& desc0,
                               const Matrix& kp1, const Matrix& desc1) {
  if (kp0.cols != 2 || kp1.cols != 2 || desc0.rows != kp0.rows || desc1.rows != kp1.rows ||
      desc0.cols != w.input_projection.in || desc1.cols != w.input_projection.in || w.layers.empty())
    throw std::invalid_argument("lighterglue: [n][2] keypoints with [n][" +
                                std::to_string(w.input_projection.in) + "] descriptors per image");
  LighterGlueOutputs out;
  out.scores = Matrix(kp0.rows, kp1.rows);
  if (!kp0.rows || !kp1.rows) return out;
  Matrix x0 = linear(desc0, w.input_projection), x1 = linear(desc1, w.input_projection);
  const Matrix f0 = rotary_frequencies(kp0, w.position), f1 = rotary_frequencies(kp1, w.position);
  const double scale =
      1.0 / std::sqrt(double(w.dim()));  // split as its square root on each side in the graph
  for (const LighterGlueWeights::Layer& L : w.layers) {
    x0 = self_block(x0, f0, L);
    x1 = self_block(x1, f1, L);
    const Matrix qk0 = linear(x0, L.cross_qk), qk1 = linear(x1, L.cross_qk);
    const Matrix v0 = linear(x0, L.cross_v), v1 = linear(x1, L.cross_v);
    Matrix a01 = multiply_transposed(qk0, qk1, scale), a10 = multiply_transposed(qk1, qk0, scale);
    softmax_rows(a01);
    softmax_rows(a10);
    const Matrix m0 = linear(multiply(a01, v1), L.cross_out), m1 = linear(multiply(a10, v0), L.cross_out);
    x0 = update(x0, m0, L.cross_ffn);
    x1 = update(x1, m1, L.cross_ffn);
  }
  const Matrix d0 = linear(x0, w.final_projection), d1 = linear(x1, w.final_projection);
  const Matrix sim = multiply_transposed(d0, d1, 1.0 / std::sqrt(double(w.dim())));  // d^-1/4 on each side
  const Matrix z0 = linear(x0, w.matchability), z1 = linear(x1, w.matchability);
  const Matrix rows = log_softmax_rows(sim), cols = log_softmax_columns(sim);
  const auto log_sigmoid = [](double z) {
    return z >= 0 ? -std::log1p(std::exp(-z)) : z - std::log1p(std::exp(z));
  };
  for (size_t i = 0; i < sim.rows; ++i)
    for (size_t j = 0; j < sim.cols; ++j)
      out.scores.at(i, j) =
          rows.at(i, j) + cols.at(i, j) + log_sigmoid(z0.at(i, 0)) + log_sigmoid(z1.at(j, 0));
  mutual_best(out.scores, out.matches, out.match_scores);
  return out;
}

}  // namespace litgs::kernels::nn
