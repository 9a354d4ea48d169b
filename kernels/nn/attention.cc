#include "kernels/nn/attention.h"

#include <stdexcept>
#include <string>

#include "kernels/elementwise.h"
#include "kernels/loss/loss_sum.h"
#include "kernels/nn/nn_shared.h"
#include "kernels/subgroup_kernel.h"

namespace litgs::kernels {

using loss_detail::check_binding;

AttentionKernels::AttentionKernels(engine::Context& context)
    : context_(&context),
      // The matrices read as texels (nn_shared.h): a vector gather on CPU drivers.
      linear_(make_kernel(context, "nn/nn_linear", NN_LINEAR_BINDING_COUNT, sizeof(NnLinearParams), {},
                          {{NN_LINEAR_BINDING_A, VK_FORMAT_R32_SFLOAT},
                           {NN_LINEAR_BINDING_B, VK_FORMAT_R32_SFLOAT},
                           {NN_LINEAR_BINDING_W, VK_FORMAT_R32_SFLOAT},
                           {NN_LINEAR_BINDING_A4, VK_FORMAT_R32G32B32A32_SFLOAT},
                           {NN_LINEAR_BINDING_B4, VK_FORMAT_R32G32B32A32_SFLOAT},
                           {NN_LINEAR_BINDING_W4, VK_FORMAT_R32G32B32A32_SFLOAT}})),
      matmul_(make_kernel(context, "nn/nn_matmul", NN_MATMUL_BINDING_COUNT, sizeof(NnMatmulParams), {},
                          {{NN_MATMUL_BINDING_A, VK_FORMAT_R32_SFLOAT},
                           {NN_MATMUL_BINDING_B, VK_FORMAT_R32_SFLOAT},
                           {NN_MATMUL_BINDING_A4, VK_FORMAT_R32G32B32A32_SFLOAT},
                           {NN_MATMUL_BINDING_B4, VK_FORMAT_R32G32B32A32_SFLOAT}})),
      rows_(make_kernel(context, "nn/nn_rows", NN_ROWS_BINDING_COUNT, sizeof(NnRowsParams), {},
                        {{NN_ROWS_BINDING_A, VK_FORMAT_R32_SFLOAT},
                         {NN_ROWS_BINDING_B, VK_FORMAT_R32_SFLOAT},
                         {NN_ROWS_BINDING_C, VK_FORMAT_R32_SFLOAT},
                         {NN_ROWS_BINDING_A4, VK_FORMAT_R32G32B32A32_SFLOAT},
                         {NN_ROWS_BINDING_B4, VK_FORMAT_R32G32B32A32_SFLOAT}})),
      softmax_(make_kernel(context, "nn/nn_softmax", NN_SOFTMAX_BINDING_COUNT, sizeof(NnSoftmaxParams), {},
                           {{NN_SOFTMAX_BINDING_A, VK_FORMAT_R32_SFLOAT},
                            {NN_SOFTMAX_BINDING_A4, VK_FORMAT_R32G32B32A32_SFLOAT}})) {}

AttentionKernels::~AttentionKernels() = default;

void AttentionKernels::linear(engine::Sequence& s, const engine::Buffer& a, uint32_t a_cols,
                              const engine::Buffer* b, uint32_t b_cols, const engine::Buffer& w,
                              const engine::Buffer* bias, const engine::Buffer* residual,
                              const engine::Buffer& y, uint32_t rows, uint32_t out) const {
  static const char* who = "AttentionKernels::linear";
  if (!rows || !out || !a_cols || (b == nullptr) != (b_cols == 0))
    throw std::invalid_argument(std::string(who) + ": empty rows, outputs or input, or b without its width");
  const uint64_t in = uint64_t{a_cols} + b_cols;
  check_binding(who, "a", a, uint64_t{rows} * a_cols * sizeof(float));
  if (b) check_binding(who, "b", *b, uint64_t{rows} * b_cols * sizeof(float));
  check_binding(who, "w", w, in * out * sizeof(float));
  if (bias) check_binding(who, "bias", *bias, uint64_t{out} * sizeof(float));
  if (residual) check_binding(who, "residual", *residual, uint64_t{rows} * out * sizeof(float));
  check_binding(who, "y", y, uint64_t{rows} * out * sizeof(float));
  NnLinearParams p{};
  p.rows = rows;
  p.a_cols = a_cols;
  p.b_cols = b_cols;
  p.outputs = out;
  p.has_bias = bias != nullptr;
  p.has_residual = residual != nullptr;
  p.quads = linear_reads_quads(a_cols, b_cols, out);
  const uint64_t row_tiles = (rows + NN_LINEAR_ROWS - 1) / NN_LINEAR_ROWS;
  const uint64_t count = p.quads ? row_tiles * (out / 4)
                                 : row_tiles * ((out + NN_LINEAR_RUN - 1) / NN_LINEAR_RUN) * NN_LINEAR_LANES;
  p.count = static_cast<uint32_t>(count);
  s.dispatch(*linear_, elementwise_groups(*context_, count, who),
             {{NN_LINEAR_BINDING_A, &a, engine::Access::kRead},
              {NN_LINEAR_BINDING_B, b ? b : &a, engine::Access::kRead},
              {NN_LINEAR_BINDING_W, &w, engine::Access::kRead},
              {NN_LINEAR_BINDING_BIAS, bias ? bias : &w, engine::Access::kRead},
              {NN_LINEAR_BINDING_R, residual ? residual : &a, engine::Access::kRead},
              {NN_LINEAR_BINDING_A4, &a, engine::Access::kRead},
              {NN_LINEAR_BINDING_B4, b ? b : &a, engine::Access::kRead},
              {NN_LINEAR_BINDING_W4, &w, engine::Access::kRead},
              {NN_LINEAR_BINDING_Y, &y, engine::Access::kWrite}},
             p);
}

bool linear_reads_quads(uint32_t a_cols, uint32_t b_cols, uint32_t out) {
  return a_cols % 4 == 0 && b_cols % 4 == 0 && out % 4 == 0;
}

bool matmul_reads_quads(const RowBlock& a, const RowBlock& b) {
  const auto aligned = [](uint64_t floats) { return floats % 4 == 0; };
  return aligned(uint64_t{a.first} * a.row_stride()) && aligned(a.row_stride()) &&
         aligned(uint64_t{b.first} * b.cols) && aligned(b.cols);
}

void AttentionKernels::matmul(engine::Sequence& s, const RowBlock& a, const RowBlock& b,
                              const engine::Buffer& y, uint32_t y_first, uint32_t y_stride, bool transposed,
                              float scale) const {
  static const char* who = "AttentionKernels: matrix product";
  if (!a.buffer || !b.buffer || !a.rows || !b.rows || !a.cols || !b.cols)
    throw std::invalid_argument(std::string(who) + ": an empty operand");
  if (transposed ? a.cols != b.cols : a.cols != b.rows)
    throw std::invalid_argument(std::string(who) + ": inner sizes differ (" + std::to_string(a.cols) +
                                " and " + std::to_string(transposed ? b.cols : b.rows) + ")");
  if (a.row_stride() < a.cols || (b.stride && b.stride != b.cols))
    throw std::invalid_argument(std::string(who) + ": a's rows narrower than its width, or b padded");
  const uint32_t m = transposed ? b.rows : b.cols;
  if (!y_stride) y_stride = m;
  if (y_stride < m) throw std::invalid_argument(std::string(who) + ": y's rows narrower than its width");
  check_binding(who, "a", *a.buffer,
                ((uint64_t{a.first} + a.rows - 1) * a.row_stride() + a.cols) * sizeof(float));
  check_binding(who, "b", *b.buffer, (uint64_t{b.first} + b.rows) * b.cols * sizeof(float));
  check_binding(who, "y", y, ((uint64_t{y_first} + a.rows - 1) * y_stride + m) * sizeof(float));
  NnMatmulParams p{};
  p.n = a.rows;
  p.m = m;
  p.k = a.cols;
  p.transposed = transposed;
  p.scale = scale;
  p.quads = matmul_reads_quads(a, b);
  const uint64_t row_tiles = (a.rows + NN_MATMUL_ROWS - 1) / NN_MATMUL_ROWS;
  const uint64_t count = p.quads ? row_tiles * ((m + 3) / 4)
                                 : row_tiles * ((m + NN_MATMUL_RUN - 1) / NN_MATMUL_RUN) * NN_MATMUL_LANES;
  p.count = static_cast<uint32_t>(count);
  p.a_stride = a.row_stride();
  p.a_offset = a.first * a.row_stride();
  p.b_offset = b.first * b.cols;
  p.y_offset = y_first * y_stride;
  p.y_stride = y_stride;
  s.dispatch(*matmul_, elementwise_groups(*context_, count, who),
             {{NN_MATMUL_BINDING_A, a.buffer, engine::Access::kRead},
              {NN_MATMUL_BINDING_B, b.buffer, engine::Access::kRead},
              {NN_MATMUL_BINDING_A4, a.buffer, engine::Access::kRead},
              {NN_MATMUL_BINDING_B4, b.buffer, engine::Access::kRead},
              {NN_MATMUL_BINDING_Y, &y, engine::Access::kWrite}},
             p);
}

void AttentionKernels::multiply_transposed(engine::Sequence& s, const RowBlock& a, const RowBlock& b,
                                           const engine::Buffer& y, float scale, uint32_t y_stride) const {
  matmul(s, a, b, y, 0, y_stride, true, scale);
}

void AttentionKernels::multiply(engine::Sequence& s, const RowBlock& a, const RowBlock& b,
                                const engine::Buffer& y, uint32_t y_first) const {
  matmul(s, a, b, y, y_first, 0, false, 1.0f);
}

void AttentionKernels::rows_op(engine::Sequence& s, uint32_t op, const engine::Buffer& a,
                               const engine::Buffer& b, const engine::Buffer& c, const engine::Buffer& out,
                               uint32_t rows, uint32_t cols, uint64_t count, float epsilon, bool quads,
                               uint32_t out_offset) const {
  if (!rows || !cols) throw std::invalid_argument("AttentionKernels: an empty matrix");
  NnRowsParams p{};
  p.op = op;
  p.rows = rows;
  p.cols = cols;
  p.count = static_cast<uint32_t>(count);
  p.epsilon = epsilon;
  p.quads = quads;
  p.out_offset = out_offset;
  // Only the quad paths read the four-float views; otherwise they are bound to an operand that holds one
  // whole texel (a pair's few matchability logits may not).
  const auto four_floats = [&](const engine::Buffer& x) {
    if (quads) return &x;
    for (const engine::Buffer* y : {&x, &a, &b, &c, &out})
      if (y->size_bytes() >= 4 * sizeof(float)) return y;
    return &x;
  };
  s.dispatch(*rows_, elementwise_groups(*context_, count, "AttentionKernels"),
             {{NN_ROWS_BINDING_A, &a, engine::Access::kRead},
              {NN_ROWS_BINDING_A4, four_floats(a), engine::Access::kRead},
              {NN_ROWS_BINDING_B4, four_floats(b), engine::Access::kRead},
              {NN_ROWS_BINDING_B, &b, engine::Access::kRead},
              {NN_ROWS_BINDING_C, &c, engine::Access::kRead},
              {NN_ROWS_BINDING_OUT, &out, engine::Access::kWrite}},
             p);
}

void AttentionKernels::layer_norm_gelu(engine::Sequence& s, const engine::Buffer& a,
                                       const engine::Buffer& scale, const engine::Buffer& bias, uint32_t rows,
                                       uint32_t cols, float epsilon) const {
  static const char* who = "AttentionKernels::layer_norm_gelu";
  check_binding(who, "a", a, uint64_t{rows} * cols * sizeof(float));
  check_binding(who, "scale", scale, uint64_t{cols} * sizeof(float));
  check_binding(who, "bias", bias, uint64_t{cols} * sizeof(float));
  rows_op(s, NN_ROWS_LAYER_NORM_GELU, a, scale, bias, a, rows, cols, rows, epsilon, cols % 4 == 0);
}

bool softmax_reads_quads(uint32_t a_stride) {
  return a_stride % 4 == 0;
}

void AttentionKernels::lines_op(engine::Sequence& s, uint32_t op, const engine::Buffer& a, uint32_t a_stride,
                                const engine::Buffer& out, uint32_t out_offset, uint32_t out_stride,
                                uint32_t rows, uint32_t cols, bool columns) const {
  static const char* who = "AttentionKernels: softmax";
  if (!rows || !cols) throw std::invalid_argument(std::string(who) + ": an empty matrix");
  const uint32_t lines = columns ? cols : rows, length = columns ? rows : cols;
  if (!a_stride) a_stride = cols;
  if (!out_stride) out_stride = length;
  if (a_stride < cols || out_stride < length)
    throw std::invalid_argument(std::string(who) + ": a row narrower than the matrix, or out's than a line");
  // Column quads read whole texels: the last quad's columns past `cols` lie inside a's row stride.
  const bool quads = softmax_reads_quads(a_stride);
  check_binding(
      who, "a", a,
      ((uint64_t{rows} - 1) * a_stride + (columns && quads ? padded_row(cols) : cols)) * sizeof(float));
  check_binding(who, "out", out,
                (uint64_t{out_offset} +
                 (op == NN_SOFTMAX_SOFTMAX ? (uint64_t{lines} - 1) * out_stride + length : lines)) *
                    sizeof(float));
  NnSoftmaxParams p{};
  p.op = op;
  p.lines = lines;
  p.line_length = length;
  p.line_step = columns ? 1 : a_stride;
  p.step = columns ? a_stride : 1;
  p.out_offset = out_offset;
  p.out_stride = out_stride;
  p.path = !quads ? NN_SOFTMAX_FLOATS : columns ? NN_SOFTMAX_COLUMN_QUADS : NN_SOFTMAX_ROW_QUADS;
  p.count = p.path == NN_SOFTMAX_COLUMN_QUADS ? (lines + 3) / 4 : lines;
  s.dispatch(*softmax_, elementwise_groups(*context_, p.count, who),
             {{NN_SOFTMAX_BINDING_A, &a, engine::Access::kRead},
              {NN_SOFTMAX_BINDING_A4, &a, engine::Access::kRead},
              {NN_SOFTMAX_BINDING_OUT, &out, engine::Access::kWrite}},
             p);
}

void AttentionKernels::softmax_rows(engine::Sequence& s, const engine::Buffer& a, const engine::Buffer& out,
                                    uint32_t rows, uint32_t cols, uint32_t out_stride,
                                    uint32_t a_stride) const {
  lines_op(s, NN_SOFTMAX_SOFTMAX, a, a_stride, out, 0, out_stride, rows, cols, false);
}

void AttentionKernels::softmax_columns(engine::Sequence& s, const engine::Buffer& a,
                                       const engine::Buffer& out, uint32_t rows, uint32_t cols,
                                       uint32_t out_stride, uint32_t a_stride) const {
  lines_op(s, NN_SOFTMAX_SOFTMAX, a, a_stride, out, 0, out_stride, rows, cols, true);
}

void AttentionKernels::assignment(engine::Sequence& s, const engine::Buffer& sim, const engine::Buffer& z,
                                  const engine::Buffer& lse, const engine::Buffer& out, uint32_t rows,
                                  uint32_t cols) const {
  static const char* who = "AttentionKernels::assignment";
  check_binding(who, "sim", sim, uint64_t{rows} * cols * sizeof(float));
  check_binding(who, "z", z, (uint64_t{rows} + cols) * sizeof(float));
  check_binding(who, "lse", lse, assignment_scratch_floats(rows, cols) * sizeof(float));
  check_binding(who, "out", out, uint64_t{rows} * cols * sizeof(float));
  const uint32_t columns = padded_row(rows), sigmoids = columns + padded_row(cols);
  lines_op(s, NN_SOFTMAX_LOG_SUM_EXP, sim, 0, lse, 0, 0, rows, cols, false);
  lines_op(s, NN_SOFTMAX_LOG_SUM_EXP, sim, 0, lse, columns, 0, rows, cols, true);
  rows_op(s, NN_ROWS_LOG_SIGMOID, z, z, z, lse, rows, cols, uint64_t{rows} + cols, 0.0f, false, sigmoids);
  const bool quads = cols % 4 == 0;
  rows_op(s, NN_ROWS_ASSIGNMENT, sim, lse, lse, out, rows, cols, uint64_t{rows} * (quads ? cols / 4 : cols),
          0.0f, quads);
}

void AttentionKernels::split_rotary(engine::Sequence& s, const engine::Buffer& qkv,
                                    const engine::Buffer& keypoints, const engine::Buffer& rotary,
                                    const engine::Buffer& out, uint32_t rows, uint32_t dim) const {
  static const char* who = "AttentionKernels::split_rotary";
  if (dim % 2) throw std::invalid_argument(std::string(who) + ": an odd width");
  check_binding(who, "qkv", qkv, uint64_t{rows} * 3 * dim * sizeof(float));
  check_binding(who, "keypoints", keypoints, uint64_t{rows} * 2 * sizeof(float));
  check_binding(who, "rotary", rotary, uint64_t{dim} * sizeof(float));
  check_binding(who, "out", out, uint64_t{rows} * 3 * dim * sizeof(float));
  rows_op(s, NN_ROWS_SPLIT_ROTARY, qkv, keypoints, rotary, out, rows, dim, uint64_t{rows} * (dim / 2), 0.0f);
}

}  // namespace litgs::kernels
