// The attention matcher's operations on the device (nn_linear.comp, nn_matmul.comp, nn_rows.comp,
// nn_softmax.comp), each tested against its CPU double reference in kernels/nn/attention_reference.h.
// Matrices are row-major float arrays, one row per keypoint; both images' rows may share a buffer (the
// matrix products take offsets).
#pragma once

#include <cstdint>
#include <memory>

#include "engine/buffer.h"
#include "engine/context.h"
#include "engine/kernel.h"
#include "engine/sequence.h"
#include "kernels/nn/nn_shared.h"

namespace litgs::kernels {

// A block of rows inside a buffer: `rows` rows of `cols` floats from row `first`, a row every `stride`
// floats (0: cols; a wider stride pads each row).
struct RowBlock {
  const engine::Buffer* buffer = nullptr;
  uint32_t first = 0, rows = 0, cols = 0, stride = 0;
  uint32_t row_stride() const { return stride ? stride : cols; }
};

// The floats of a row of `cols` padded to a four-float boundary: the matrix products read such rows as
// four-float texels.
inline uint32_t padded_row(uint32_t cols) {
  return NN_PADDED_ROW(cols);
}

// The floats AttentionKernels::assignment's lse buffer holds for a [rows][cols] similarity.
inline uint64_t assignment_scratch_floats(uint32_t rows, uint32_t cols) {
  return 2 * (uint64_t{padded_row(rows)} + padded_row(cols));
}

// Whether the softmax reads a's rows (columns: false) or four neighbouring columns (true) as four-float
// texels (nn_softmax.comp's quad layouts): a's rows, a_stride floats apart, start on four-float boundaries.
bool softmax_reads_quads(uint32_t a_stride);

// Whether the linear layers read their rows and weights as four-float texels (nn_linear.comp's quad path):
// the widths of a and b (0 without b) and the outputs are multiples of four.
bool linear_reads_quads(uint32_t a_cols, uint32_t b_cols, uint32_t out);

// Whether the matrix products read a and b as four-float texels (nn_matmul.comp's quad path): every row of
// a and of b starts on a four-float boundary, and b's rows (along k for a b^T, along the columns for a b)
// are whole texels. a's rows need not be: their last floats past a whole texel are read one at a time.
bool matmul_reads_quads(const RowBlock& a, const RowBlock& b);

class AttentionKernels {
 public:
  explicit AttentionKernels(engine::Context& context);
  ~AttentionKernels();
  // y [rows][out] = [a | b] w + bias (+ residual); b, bias and residual may be null (b's columns then 0).
  void linear(engine::Sequence& s, const engine::Buffer& a, uint32_t a_cols, const engine::Buffer* b,
              uint32_t b_cols, const engine::Buffer& w, const engine::Buffer* bias,
              const engine::Buffer* residual, const engine::Buffer& y, uint32_t rows, uint32_t out) const;
  // y = scale a b^T: [a.rows][b.rows], a row every y_stride floats (0: b.rows), a and b of one width.
  void multiply_transposed(engine::Sequence& s, const RowBlock& a, const RowBlock& b, const engine::Buffer& y,
                           float scale, uint32_t y_stride = 0) const;
  // y (its rows from y_first, b.cols wide) = a b: a [a.rows][b.rows] (a may be padded; b may not).
  void multiply(engine::Sequence& s, const RowBlock& a, const RowBlock& b, const engine::Buffer& y,
                uint32_t y_first) const;
  // a [rows][cols] = gelu(layer_norm(a) * scale + bias), in place.
  void layer_norm_gelu(engine::Sequence& s, const engine::Buffer& a, const engine::Buffer& scale,
                       const engine::Buffer& bias, uint32_t rows, uint32_t cols, float epsilon) const;
  // out [rows][cols] = the softmax of each row of a [rows][cols]; a row of a every a_stride floats, of out
  // every out_stride (0: cols).
  void softmax_rows(engine::Sequence& s, const engine::Buffer& a, const engine::Buffer& out, uint32_t rows,
                    uint32_t cols, uint32_t out_stride = 0, uint32_t a_stride = 0) const;
  // out [cols][rows] = the softmax of each column of a [rows][cols], as a row (every out_stride floats, 0:
  // rows); a row of a every a_stride floats (0: cols).
  void softmax_columns(engine::Sequence& s, const engine::Buffer& a, const engine::Buffer& out, uint32_t rows,
                       uint32_t cols, uint32_t out_stride = 0, uint32_t a_stride = 0) const;
  // out [rows][cols]: the log assignment of sim [rows][cols] with the matchability logits z [rows + cols]
  // (the first image's, then the second's). On the way lse [assignment_scratch_floats] gets the rows' and the
  // columns' log-sum-exps, then the log-sigmoids of z, each part from a four-float boundary (nn_shared.h).
  void assignment(engine::Sequence& s, const engine::Buffer& sim, const engine::Buffer& z,
                  const engine::Buffer& lse, const engine::Buffer& out, uint32_t rows, uint32_t cols) const;
  // out [3][rows][dim]: q and k rotated by the keypoints' frequencies, and v, from qkv [rows][3 dim]
  // (interleaved per channel), keypoints [rows][2] and the rotary weights [2][dim / 2].
  void split_rotary(engine::Sequence& s, const engine::Buffer& qkv, const engine::Buffer& keypoints,
                    const engine::Buffer& rotary, const engine::Buffer& out, uint32_t rows,
                    uint32_t dim) const;

 private:
  void rows_op(engine::Sequence& s, uint32_t op, const engine::Buffer& a, const engine::Buffer& b,
               const engine::Buffer& c, const engine::Buffer& out, uint32_t rows, uint32_t cols,
               uint64_t count, float epsilon, bool quads = false, uint32_t out_offset = 0) const;
  void matmul(engine::Sequence& s, const RowBlock& a, const RowBlock& b, const engine::Buffer& y,
              uint32_t y_first, uint32_t y_stride, bool transposed, float scale) const;
  // Each row's (columns: false) or each column's softmax or log-sum-exp (nn_softmax.comp).
  void lines_op(engine::Sequence& s, uint32_t op, const engine::Buffer& a, uint32_t a_stride,
                const engine::Buffer& out, uint32_t out_offset, uint32_t out_stride, uint32_t rows,
                uint32_t cols, bool columns) const;
  engine::Context* context_;
  std::unique_ptr<engine::Kernel> linear_, matmul_, rows_, softmax_;
};

}  // namespace litgs::kernels
