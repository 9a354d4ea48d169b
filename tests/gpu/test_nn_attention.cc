// The attention matcher on the device (kernels/nn/attention.h, lighterglue.h) against its double-precision
// CPU references (kernels/nn/attention_reference.h, lighterglue_reference.h), validation layer on: each
// operation on random inputs (linear with a concatenated input, bias and residual; the matrix products at
// row offsets; layer norm with GELU; the softmax of rows and of columns; the log assignment; q, k, v split
// with the rotary encoding), then the whole matcher on the inputs of tests/data/lighterglue/ (the same
// matches; scores within the float32 spread measured against onnxruntime there), bit-identical twice, and the
// hard cases: an image without keypoints, wrong sizes. Tolerances (float against double): each operation
// within 1e-5 of its largest output (GELU's erf approximation: 1.5e-7).
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstddef>
#include <random>
#include <string>
#include <utility>
#include <vector>

#include "engine/buffer.h"
#include "engine/sequence.h"
#include "gpu_test.h"
#include "host/nn/lighterglue_weights.h"
#include "io/onnx_model.h"
#include "kernels/nn/attention.h"
#include "kernels/nn/lighterglue.h"
#include "kernels/nn/lighterglue_reference.h"
#include "tests/support/lighterglue_inputs.h"

namespace litgs {
namespace {

using engine::DeviceArray;
using kernels::RowBlock;
using kernels::nn::Matrix;

Matrix random_matrix(size_t rows, size_t cols, uint32_t seed, double spread = 1.0) {
  std::mt19937 rng(seed);
  std::normal_distribution<float> n(0.0f, static_cast<float>(spread));
  Matrix m(rows, cols);
  for (double& v : m.values) v = n(rng);  // float values, as the device holds them
  return m;
}

std::vector<float> floats(const Matrix& m) {
  return std::vector<float>(m.values.begin(), m.values.end());
}
std::vector<float> floats(const std::vector<double>& v) {
  return std::vector<float>(v.begin(), v.end());
}

// The largest difference over the largest reference magnitude.
double relative_error(const std::vector<float>& device, const std::vector<double>& reference) {
  EXPECT_EQ(device.size(), reference.size());
  double worst = 0, largest = 1e-30;
  for (size_t i = 0; i < device.size() && i < reference.size(); ++i) {
    worst = std::max(worst, std::abs(double(device[i]) - reference[i]));
    largest = std::max(largest, std::abs(reference[i]));
  }
  return worst / largest;
}

kernels::nn::LighterGlueWeights weights() {
  return host::nn::lighterglue_weights(
      io::read_onnx_model(std::string(LITGS_NN_MODELS) + "/lighterglue/lighterglue_L3.onnx"));
}

class NnAttentionTest : public testing::GpuTest {
 protected:
  std::unique_ptr<DeviceArray<float>> upload(const std::vector<float>& v, const char* name = "test: array") {
    auto a = std::make_unique<DeviceArray<float>>(context(), name, v.size());
    a->upload(v);
    return a;
  }
};

TEST_F(NnAttentionTest, EachOperationMatchesItsReference) {
  kernels::AttentionKernels ops(context());
  // Linear over [a | b] with a bias and a residual; 19 rows and 45 outputs: a whole tile and a partial one
  // of NN_LINEAR_ROWS rows, a whole run and a partial one of NN_LINEAR_RUN outputs.
  const uint32_t n = 19, outputs = 45;
  const Matrix a = random_matrix(n, 5, 1), b = random_matrix(n, 3, 2), r = random_matrix(n, outputs, 3);
  kernels::nn::LinearWeights w{8, outputs, floats(random_matrix(8, outputs, 4).values),
                               floats(random_matrix(1, outputs, 5).values)};
  const Matrix expected = kernels::nn::add(kernels::nn::linear(kernels::nn::concat_columns(a, b), w), r);
  auto da = upload(floats(a)), db = upload(floats(b)), dr = upload(floats(r)), dw = upload(w.weight),
       dbias = upload(w.bias);
  DeviceArray<float> y(context(), "test: y", n * outputs);
  {
    engine::Sequence s(context());
    ops.linear(s, da->buffer(), 5, &db->buffer(), 3, dw->buffer(), &dbias->buffer(), &dr->buffer(),
               y.buffer(), n, outputs);
    s.submit_and_wait();
  }
  EXPECT_LT(relative_error(y.download(), expected.values), 1e-5);
  EXPECT_FALSE(kernels::linear_reads_quads(5, 3, outputs));

  // The same on the quad path (widths that are multiples of four): a 8 and b 4 columns wide, 12 outputs.
  const Matrix a8 = random_matrix(n, 8, 22), b4 = random_matrix(n, 4, 23), r12 = random_matrix(n, 12, 24);
  kernels::nn::LinearWeights w12{12, 12, floats(random_matrix(12, 12, 25).values),
                                 floats(random_matrix(1, 12, 26).values)};
  const Matrix expected12 =
      kernels::nn::add(kernels::nn::linear(kernels::nn::concat_columns(a8, b4), w12), r12);
  auto da8 = upload(floats(a8)), db4 = upload(floats(b4)), dr12 = upload(floats(r12)),
       dw12 = upload(w12.weight), dbias12 = upload(w12.bias);
  DeviceArray<float> y12(context(), "test: y", n * 12);
  EXPECT_TRUE(kernels::linear_reads_quads(8, 4, 12));
  {
    engine::Sequence s(context());
    ops.linear(s, da8->buffer(), 8, &db4->buffer(), 4, dw12->buffer(), &dbias12->buffer(), &dr12->buffer(),
               y12.buffer(), n, 12);
    s.submit_and_wait();
  }
  EXPECT_LT(relative_error(y12.download(), expected12.values), 1e-5);

  // Products at row offsets: rows 2..6 of p against rows 1..4 of q (transposed), then against q's rows as b.
  const Matrix p = random_matrix(9, 6, 6), q = random_matrix(8, 6, 7), v = random_matrix(8, 5, 8);
  Matrix p_rows(5, 6), q_rows(4, 6), v_rows(4, 5);
  for (size_t i = 0; i < 5; ++i)
    for (size_t k = 0; k < 6; ++k) p_rows.at(i, k) = p.at(2 + i, k);
  for (size_t i = 0; i < 4; ++i) {
    for (size_t k = 0; k < 6; ++k) q_rows.at(i, k) = q.at(1 + i, k);
    for (size_t k = 0; k < 5; ++k) v_rows.at(i, k) = v.at(3 + i, k);
  }
  const Matrix sim = kernels::nn::multiply_transposed(p_rows, q_rows, 0.3);
  const Matrix product = kernels::nn::multiply(sim, v_rows);
  auto dp = upload(floats(p)), dq = upload(floats(q)), dv = upload(floats(v));
  DeviceArray<float> dsim(context(), "test: sim", 5 * 4), dproduct(context(), "test: product", 7 * 5);
  {
    engine::Sequence s(context());
    ops.multiply_transposed(s, RowBlock{&dp->buffer(), 2, 5, 6}, RowBlock{&dq->buffer(), 1, 4, 6},
                            dsim.buffer(), 0.3f);
    ops.multiply(s, RowBlock{&dsim.buffer(), 0, 5, 4}, RowBlock{&dv->buffer(), 3, 4, 5}, dproduct.buffer(),
                 2);
    s.submit_and_wait();
  }
  EXPECT_LT(relative_error(dsim.download(), sim.values), 1e-5);
  const std::vector<float> product_rows = dproduct.download(2 * 5, 5 * 5);  // written from row 2
  EXPECT_LT(relative_error(product_rows, product.values), 1e-5);
  EXPECT_FALSE(
      kernels::matmul_reads_quads(RowBlock{&dp->buffer(), 2, 5, 6}, RowBlock{&dq->buffer(), 1, 4, 6}));

  // The same on the quad path (rows on four-float boundaries): 19 rows, a whole tile of NN_MATMUL_ROWS and a
  // partial one; a b^T with 7 columns (a whole quad and a partial one) over k = 12; then a b with a padded
  // to rows of 16 floats over k = 13 (three quads and one float), b 8 columns wide from its row 3. The
  // padding holds NaN: a product that read it would show it.
  const Matrix p19 = random_matrix(21, 12, 18), q7 = random_matrix(9, 12, 19), w13 = random_matrix(16, 8, 20);
  Matrix p19_rows(19, 12), q7_rows(7, 12), a13(19, 13), w13_rows(13, 8);
  for (size_t i = 0; i < 19; ++i)
    for (size_t k = 0; k < 12; ++k) p19_rows.at(i, k) = p19.at(2 + i, k);
  for (size_t i = 0; i < 7; ++i)
    for (size_t k = 0; k < 12; ++k) q7_rows.at(i, k) = q7.at(1 + i, k);
  std::vector<float> padded(19 * 16, std::nanf(""));
  const Matrix a13_values = random_matrix(19, 13, 21);
  for (size_t i = 0; i < 19; ++i)
    for (size_t k = 0; k < 13; ++k)
      padded[i * 16 + k] = static_cast<float>(a13.at(i, k) = a13_values.at(i, k));
  for (size_t k = 0; k < 13; ++k)
    for (size_t j = 0; j < 8; ++j) w13_rows.at(k, j) = w13.at(3 + k, j);
  const Matrix sim19 = kernels::nn::multiply_transposed(p19_rows, q7_rows, 0.3);
  const Matrix product19 = kernels::nn::multiply(a13, w13_rows);
  auto dp19 = upload(floats(p19)), dq7 = upload(floats(q7)), da13 = upload(padded),
       dw13 = upload(floats(w13));
  const RowBlock p_block{&dp19->buffer(), 2, 19, 12}, q_block{&dq7->buffer(), 1, 7, 12},
      a_block{&da13->buffer(), 0, 19, 13, 16}, w_block{&dw13->buffer(), 3, 13, 8};
  EXPECT_TRUE(kernels::matmul_reads_quads(p_block, q_block));
  EXPECT_TRUE(kernels::matmul_reads_quads(a_block, w_block));
  DeviceArray<float> dsim19(context(), "test: sim", 19 * 7), dproduct19(context(), "test: product", 19 * 8),
      dsim19_padded(context(), "test: sim", 19 * 8);
  {
    engine::Sequence s(context());
    ops.multiply_transposed(s, p_block, q_block, dsim19.buffer(), 0.3f);
    ops.multiply_transposed(s, p_block, q_block, dsim19_padded.buffer(), 0.3f, 8);  // rows of 8 floats
    ops.multiply(s, a_block, w_block, dproduct19.buffer(), 0);
    s.submit_and_wait();
  }
  EXPECT_LT(relative_error(dsim19.download(), sim19.values), 1e-5);
  const std::vector<float> sim19_padded = dsim19_padded.download();
  for (size_t i = 0; i < 19; ++i)
    for (size_t j = 0; j < 7; ++j) EXPECT_EQ(sim19_padded[i * 8 + j], dsim19.download()[i * 7 + j]);
  EXPECT_LT(relative_error(dproduct19.download(), product19.values), 1e-5);

  // Layer norm then GELU, in place: rows of 192 (LighterGlue's, read four floats at a time) and of 190 (one
  // float at a time). And softmax.
  Matrix h = random_matrix(6, 192, 9, 3.0), h190 = random_matrix(6, 190, 18, 3.0);
  const kernels::nn::LayerNormWeights norm{floats(random_matrix(1, 192, 10).values),
                                           floats(random_matrix(1, 192, 11).values), 1e-5};
  const kernels::nn::LayerNormWeights norm190{floats(random_matrix(1, 190, 19).values),
                                              floats(random_matrix(1, 190, 20).values), 1e-5};
  auto dh = upload(floats(h)), dscale = upload(norm.scale), dshift = upload(norm.bias);
  auto dh190 = upload(floats(h190)), dscale190 = upload(norm190.scale), dshift190 = upload(norm190.bias);
  Matrix soft = random_matrix(5, 37, 12, 20.0);  // spread 20: the largest must be subtracted
  Matrix soft_columns(37, 5);                    // its columns as rows
  for (size_t i = 0; i < 5; ++i)
    for (size_t j = 0; j < 37; ++j) soft_columns.at(j, i) = soft.at(i, j);
  auto dsoft = upload(floats(soft));
  // The same matrix with rows of 40 floats, the padding NaN: the quad layouts (rows read four floats at a
  // time with a last float alone; four columns per invocation, the last four one column and three of
  // padding).
  std::vector<float> soft_padded(5 * 40, std::nanf(""));
  for (size_t i = 0; i < 5; ++i)
    for (size_t j = 0; j < 37; ++j) soft_padded[i * 40 + j] = static_cast<float>(soft.at(i, j));
  auto dsoft_padded = upload(soft_padded);
  EXPECT_FALSE(kernels::softmax_reads_quads(37));
  EXPECT_TRUE(kernels::softmax_reads_quads(40));
  DeviceArray<float> rows_out(context(), "test: softmax", 5 * 37),
      columns_out(context(), "test: softmax", 37 * 5), padded_out(context(), "test: softmax", 37 * 8),
      rows_quads(context(), "test: softmax", 5 * 37), columns_quads(context(), "test: softmax", 37 * 5);
  {
    engine::Sequence s(context());
    ops.layer_norm_gelu(s, dh->buffer(), dscale->buffer(), dshift->buffer(), 6, 192, 1e-5f);
    ops.layer_norm_gelu(s, dh190->buffer(), dscale190->buffer(), dshift190->buffer(), 6, 190, 1e-5f);
    ops.softmax_rows(s, dsoft->buffer(), rows_out.buffer(), 5, 37);
    ops.softmax_columns(s, dsoft->buffer(), columns_out.buffer(), 5, 37);
    ops.softmax_columns(s, dsoft->buffer(), padded_out.buffer(), 5, 37, 8);  // rows padded to 8 floats
    ops.softmax_rows(s, dsoft_padded->buffer(), rows_quads.buffer(), 5, 37, 0, 40);
    ops.softmax_columns(s, dsoft_padded->buffer(), columns_quads.buffer(), 5, 37, 0, 40);
    s.submit_and_wait();
  }
  kernels::nn::layer_norm(h, norm);
  kernels::nn::gelu(h);
  kernels::nn::layer_norm(h190, norm190);
  kernels::nn::gelu(h190);
  kernels::nn::softmax_rows(soft);
  kernels::nn::softmax_rows(soft_columns);
  EXPECT_LT(relative_error(dh->download(), h.values), 1e-5);
  EXPECT_LT(relative_error(dh190->download(), h190.values), 1e-5);
  EXPECT_LT(relative_error(rows_out.download(), soft.values), 1e-5);
  EXPECT_LT(relative_error(columns_out.download(), soft_columns.values), 1e-5);
  EXPECT_EQ(rows_quads.download(), rows_out.download()) << "each line's values in the same order";
  EXPECT_EQ(columns_quads.download(), columns_out.download());
  const std::vector<float> padded_rows = padded_out.download();
  std::vector<float> unpadded;
  for (size_t j = 0; j < 37; ++j)
    unpadded.insert(unpadded.end(), &padded_rows[j * 8], &padded_rows[j * 8 + 5]);
  EXPECT_LT(relative_error(unpadded, soft_columns.values), 1e-5);

  // The log assignment with matchability logits: 6 x 9 (an entry per invocation) and 5 x 8 (four per
  // invocation); neither's row count is a multiple of four, so the columns' part of lse starts after padding.
  const auto log_sigmoid = [](double x) { return -std::log1p(std::exp(-x)); };
  for (const auto& [n0, n1] : {std::pair<uint32_t, uint32_t>{6, 9}, {5, 8}}) {
    SCOPED_TRACE(std::to_string(n0) + " x " + std::to_string(n1));
    const Matrix logits = random_matrix(n0, n1, 13 + n1, 5.0), z = random_matrix(n0 + n1, 1, 14, 2.0);
    const Matrix rows = kernels::nn::log_softmax_rows(logits),
                 cols = kernels::nn::log_softmax_columns(logits);
    Matrix assignment(n0, n1);
    for (size_t i = 0; i < n0; ++i)
      for (size_t j = 0; j < n1; ++j)
        assignment.at(i, j) =
            rows.at(i, j) + cols.at(i, j) + log_sigmoid(z.values[i]) + log_sigmoid(z.values[n0 + j]);
    auto dlogits = upload(floats(logits)), dz = upload(floats(z));
    DeviceArray<float> lse(context(), "test: lse", kernels::assignment_scratch_floats(n0, n1)),
        dassign(context(), "test: assignment", size_t{n0} * n1);
    {
      engine::Sequence s(context());
      ops.assignment(s, dlogits->buffer(), dz->buffer(), lse.buffer(), dassign.buffer(), n0, n1);
      s.submit_and_wait();
    }
    EXPECT_LT(relative_error(dassign.download(), assignment.values), 1e-5);
    // The rows' and the columns' log-sum-exps on their way, then the logits' log-sigmoids, each part from a
    // four-float boundary.
    const std::vector<float> scratch = lse.download();
    const size_t columns = kernels::padded_row(n0), sigmoids = columns + kernels::padded_row(n1);
    std::vector<double> scratch_expected;
    std::vector<float> got;
    for (size_t i = 0; i < n0; ++i) {
      scratch_expected.push_back(logits.at(i, 0) - rows.at(i, 0));
      got.push_back(scratch[i]);
      scratch_expected.push_back(log_sigmoid(z.values[i]));
      got.push_back(scratch[sigmoids + i]);
    }
    for (size_t j = 0; j < n1; ++j) {
      scratch_expected.push_back(logits.at(0, j) - cols.at(0, j));
      got.push_back(scratch[columns + j]);
      scratch_expected.push_back(log_sigmoid(z.values[n0 + j]));
      got.push_back(scratch[sigmoids + columns + j]);
    }
    EXPECT_LT(relative_error(got, scratch_expected), 1e-5);
  }
  // Rotary: q, k, v interleaved per channel, 10 rows of width 8.
  const Matrix qkv = random_matrix(10, 24, 15), points = random_matrix(10, 2, 16, 0.5);
  const std::vector<float> rotary = floats(random_matrix(1, 8, 17, 3.0).values);
  auto dqkv = upload(floats(qkv)), dpoints = upload(floats(points)), drotary = upload(rotary);
  DeviceArray<float> dsplit(context(), "test: split", 10 * 24);
  {
    engine::Sequence s(context());
    ops.split_rotary(s, dqkv->buffer(), dpoints->buffer(), drotary->buffer(), dsplit.buffer(), 10, 8);
    s.submit_and_wait();
  }
  Matrix qs(10, 8), ks(10, 8), vs(10, 8);
  for (size_t row = 0; row < 10; ++row)
    for (size_t d = 0; d < 8; ++d) {
      qs.at(row, d) = qkv.at(row, 3 * d);
      ks.at(row, d) = qkv.at(row, 3 * d + 1);
      vs.at(row, d) = qkv.at(row, 3 * d + 2);
    }
  const Matrix f = kernels::nn::rotary_frequencies(points, rotary);
  kernels::nn::apply_rotary(qs, f);
  kernels::nn::apply_rotary(ks, f);
  std::vector<double> split_expected = qs.values;
  split_expected.insert(split_expected.end(), ks.values.begin(), ks.values.end());
  split_expected.insert(split_expected.end(), vs.values.begin(), vs.values.end());
  EXPECT_LT(relative_error(dsplit.download(), split_expected), 1e-5);
}

TEST_F(NnAttentionTest, LighterGlueMatchesTheReferenceAndIsDeterministic) {
  namespace in = testing::lighterglue_inputs;
  const kernels::nn::LighterGlueWeights w = weights();
  const kernels::nn::LighterGlueOutputs ref =
      kernels::nn::lighterglue(w, in::keypoints0(), in::descriptors0(), in::keypoints1(), in::descriptors1());
  const kernels::LighterGlueNetwork network(context(), w);
  const auto run = [&] {
    return network.match(floats(in::keypoints0()), floats(in::descriptors0()), floats(in::keypoints1()),
                         floats(in::descriptors1()));
  };
  const kernels::LighterGlueMatches out = run();
  ASSERT_EQ(out.scores.size(), ref.scores.values.size());
  double worst = 0;
  for (size_t i = 0; i < out.scores.size(); ++i)
    worst = std::max(worst, std::abs(out.scores[i] - ref.scores.values[i]) /
                                std::max(1.0, std::abs(ref.scores.values[i])));
  EXPECT_LT(worst, 3e-3) << "onnxruntime's float32 spread (tests/data/lighterglue)";
  EXPECT_EQ(out.matches, ref.matches);
  const kernels::LighterGlueMatches again = run();
  EXPECT_EQ(again.scores, out.scores) << "not bit-identical";
}

// A pair's matchability logits fill less than one four-float texel: the row operations still bind and the
// scores match the reference.
TEST_F(NnAttentionTest, OneKeypointPerImageMatchesTheReference) {
  namespace in = testing::lighterglue_inputs;
  const kernels::nn::LighterGlueWeights w = weights();
  const auto first_row = [](const Matrix& m) {
    Matrix row(1, m.cols);
    row.values.assign(m.values.begin(), m.values.begin() + static_cast<std::ptrdiff_t>(m.cols));
    return row;
  };
  const Matrix k0 = first_row(in::keypoints0()), d0 = first_row(in::descriptors0()),
               k1 = first_row(in::keypoints1()), d1 = first_row(in::descriptors1());
  const kernels::nn::LighterGlueOutputs ref = kernels::nn::lighterglue(w, k0, d0, k1, d1);
  const kernels::LighterGlueNetwork network(context(), w);
  const kernels::LighterGlueMatches out = network.match(floats(k0), floats(d0), floats(k1), floats(d1));
  ASSERT_EQ(out.scores.size(), 1u);
  ASSERT_TRUE(std::isfinite(out.scores[0]));
  EXPECT_NEAR(out.scores[0], ref.scores.values[0], 3e-3 * std::max(1.0, std::abs(ref.scores.values[0])));
  EXPECT_EQ(out.matches, ref.matches);
}

TEST_F(NnAttentionTest, NoKeypointsGiveNoMatchesAndWrongSizesAreRefused) {
  namespace in = testing::lighterglue_inputs;
  const kernels::LighterGlueNetwork network(context(), weights());
  const kernels::LighterGlueMatches none =
      network.match({}, {}, floats(in::keypoints1()), floats(in::descriptors1()));
  EXPECT_TRUE(none.matches.empty());
  EXPECT_THROW(
      network.match({0.1f, 0.2f}, std::vector<float>(32, 0.1f), {0.1f, 0.2f}, std::vector<float>(64, 0.1f)),
      std::invalid_argument);
  kernels::AttentionKernels ops(context());
  DeviceArray<float> small(context(), "test: small", 4);
  engine::Sequence s(context());
  EXPECT_THROW(ops.multiply_transposed(s, RowBlock{&small.buffer(), 0, 2, 3},
                                       RowBlock{&small.buffer(), 0, 2, 2}, small.buffer(), 1.0f),
               std::invalid_argument);
}

}  // namespace
}  // namespace litgs
