// The network kernels' shared contract (C++ and GLSL): bindings and parameters. Feature maps are float
// [channels][height][width]; weights are ONNX Conv's [out][in][k][k] and a bias per output channel.
#ifndef LITGS_KERNELS_NN_SHARED_H
#define LITGS_KERNELS_NN_SHARED_H

#ifdef __cplusplus
#include <cstdint>
namespace litgs::kernels {
using uint = uint32_t;
#endif

// ---- nn_conv2d.comp: one invocation per NN_CONV_OUTPUTS output channels at NN_CONV_PIXELS neighbouring
// pixels of a row (a register tile: each weight loaded once for the pixels, each input value for the
// channels) ----
#define NN_CONV_OUTPUTS 8  // a multiple of 4: the packed weights serve four channels per fetch
#define NN_CONV_PIXELS 4
#define NN_CONV_LANES 8  // invocations that interleave their pixels over one run of a row
#define NN_CONV_RUN (NN_CONV_LANES * NN_CONV_PIXELS)
#define NN_CONV_GROUP_SIZE 64       // tiles of one channel block per workgroup; the grid's y is the block
#define NN_CONV_BINDING_IN 0        // [C_in][H_in][W_in] (R32_SFLOAT texels)
#define NN_CONV_BINDING_WEIGHT 1    // [ceil(C_out / 4)][C_in][k][k][4] vec4 texels (pack_conv_weights)
#define NN_CONV_BINDING_BIAS 2      // [C_out]
#define NN_CONV_BINDING_OUT 3       // [C_out][H_out][W_out] (out)
#define NN_CONV_BINDING_IN4 4       // the input again, as R32G32B32A32_SFLOAT texels (the row paths)
#define NN_CONV_BINDING_RESIDUAL 5  // [C_out][H_out][W_out] added after the activation (else: bias)
#define NN_CONV_BINDING_COUNT 6

#define NN_ACTIVATION_NONE 0
#define NN_ACTIVATION_RELU 1
#define NN_ACTIVATION_SIGMOID 2

struct NnConvParams {
  uint in_channels, in_height, in_width;
  uint out_channels, out_height, out_width;
  uint kernel, stride, pad;
  uint activation;    // NN_ACTIVATION_* on the output
  uint has_residual;  // 1: the residual map is added to the activated output
  uint count;         // invocations per channel block: out_height * runs per row * NN_CONV_LANES
};

// ---- nn_map.comp: one invocation per output element; p.op chooses what it computes ----
#define NN_MAP_ADD 0           // out = a + b (same shape)
#define NN_MAP_AVERAGE_POOL 1  // out = mean of a's k x k window every k pixels (no padding)
#define NN_MAP_RESIZE 2        // out = a resized bilinearly, half-pixel centres, clamped (ONNX Resize linear)
#define NN_MAP_UNFOLD 3  // out channel ky k + kx = a one-channel image's pixel (ky, kx) of each k x k block
#define NN_MAP_ADD_RESIZED 4  // out = b + a resized as NN_MAP_RESIZE does (b and out of the output's shape)
#define NN_MAP_BINDING_A 0    // the maps (A and B): R32_SFLOAT texels
#define NN_MAP_BINDING_B 1  // the second operand of NN_MAP_ADD and NN_MAP_ADD_RESIZED (bound to a otherwise)
#define NN_MAP_BINDING_OUT 2
#define NN_MAP_BINDING_COUNT 3

struct NnMapParams {
  uint op;
  uint channels, in_height, in_width;  // of a
  uint out_channels, out_height, out_width;
  uint k;      // window of the pool and the unfold
  uint count;  // out_channels * out_height * out_width
};

// ---- nn_keypoints.comp: XFeat's post-processing (kernels/nn/xfeat_keypoints_reference.h); one invocation
// per 1/8-resolution cell (HEATMAP), per 1/8-resolution pixel (NORMALIZE: its channels), per output pixel
// (SCORES) or per keypoint (DESCRIPTORS) ----
#define NN_KEYPOINTS_HEATMAP 0  // out [H][W] = softmax over a's 65 bins, bin ky*8+kx at (8cy+ky, 8cx+kx)
#define NN_KEYPOINTS_SCORES 1   // out [H][W] = heat a * reliability b (bilinear) at window maxima > threshold
#define NN_KEYPOINTS_NORMALIZE 2    // out [C][h][w] = a divided by its L2 norm over the channels
#define NN_KEYPOINTS_DESCRIPTORS 3  // out [count][C] = a bicubic at b's (x, y) pairs, L2-normalized
#define NN_KEYPOINTS_BINDING_A 0
#define NN_KEYPOINTS_BINDING_B 1
#define NN_KEYPOINTS_BINDING_OUT 2
#define NN_KEYPOINTS_BINDING_COUNT 3
#define NN_KEYPOINTS_MAX_CHANNELS 64  // descriptors' channels (one invocation holds them)

struct NnKeypointsParams {
  uint op;
  uint channels, map_height, map_width;  // the 1/8-resolution maps
  uint height, width;                    // the image (8 map_height x 8 map_width)
  uint window;                           // NMS window (odd)
  uint count;                            // invocations (the op's cells, pixels or keypoints)
  float threshold;
};

// ---- The attention matcher (LighterGlue; kernels/nn/attention_reference.h): matrices are row-major, one
// row per keypoint ----

// nn_linear.comp: y = [a | b] w + bias (+ r): one invocation per tile of NN_LINEAR_ROWS rows x
// NN_LINEAR_OUTPUTS outputs. Quad path (p.quads, where a's, b's and the outputs' widths are multiples of
// four: linear_reads_quads in attention.h): the tile's outputs neighbours, the rows and the weights read as
// four-float texels. Generic path: the outputs interleaved over NN_LINEAR_LANES neighbouring invocations.
#define NN_LINEAR_ROWS 8
#define NN_LINEAR_OUTPUTS 4
#define NN_LINEAR_LANES 8
#define NN_LINEAR_RUN (NN_LINEAR_LANES * NN_LINEAR_OUTPUTS)
#define NN_LINEAR_BINDING_A 0     // [rows][a_cols] (A, B and W: R32_SFLOAT texels)
#define NN_LINEAR_BINDING_B 1     // [rows][b_cols], concatenated after a's columns (bound to a without)
#define NN_LINEAR_BINDING_W 2     // [a_cols + b_cols][out]
#define NN_LINEAR_BINDING_BIAS 3  // [out] (bound to w without)
#define NN_LINEAR_BINDING_R 4     // [rows][out], added (bound to a without)
#define NN_LINEAR_BINDING_Y 5     // [rows][out] (out)
#define NN_LINEAR_BINDING_A4 6    // A, B and W again, as R32G32B32A32_SFLOAT texels (the quad path)
#define NN_LINEAR_BINDING_B4 7
#define NN_LINEAR_BINDING_W4 8
#define NN_LINEAR_BINDING_COUNT 9

struct NnLinearParams {
  uint rows, a_cols, b_cols, outputs;
  uint has_bias, has_residual;
  uint count;  // generic: ceil(rows / ROWS) ceil(out / RUN) LANES; quads: ceil(rows / ROWS) out / 4
  uint quads;  // 1: the quad path
};

// nn_matmul.comp: y = scale a b^T (a [n][k], b [m][k]; transposed) or y = a b (a [n][k], b [k][m]).
// Generic path: one invocation per tile of NN_MATMUL_ROWS rows x NN_MATMUL_OUTPUTS columns, the columns
// interleaved over NN_MATMUL_LANES neighbouring invocations. Quad path (p.quads, where the operands' rows
// start on four-float boundaries: matmul_reads_quads in attention.h): one invocation per NN_MATMUL_ROWS
// rows x 4 neighbouring columns, a read as four-float texels along k, b along k (a b^T) or along its
// columns (a b).
#define NN_MATMUL_ROWS 16
#define NN_MATMUL_OUTPUTS 4
#define NN_MATMUL_LANES 8
#define NN_MATMUL_RUN (NN_MATMUL_LANES * NN_MATMUL_OUTPUTS)
#define NN_MATMUL_BINDING_A 0  // A and B: R32_SFLOAT texels
#define NN_MATMUL_BINDING_B 1
#define NN_MATMUL_BINDING_Y 2
#define NN_MATMUL_BINDING_A4 3  // A and B again, as R32G32B32A32_SFLOAT texels (the quad path)
#define NN_MATMUL_BINDING_B4 4
#define NN_MATMUL_BINDING_COUNT 5

struct NnMatmulParams {
  uint n, m, k;
  uint transposed;  // 1: a b^T
  float scale;
  uint count;     // generic: ceil(n / ROWS) ceil(m / RUN) LANES; quads: ceil(n / ROWS) ceil(m / 4)
  uint quads;     // 1: the quad path
  uint a_stride;  // floats from one row of a to the next (>= k: a padded row)
  uint a_offset, b_offset, y_offset;  // in floats: both images' rows share one buffer
  uint y_stride;                      // floats from one row of y to the next (>= m: a padded row)
};

// The floats of a row of n padded to a four-float boundary, where the kernels read rows as four-float texels.
#define NN_PADDED_ROW(n) ((((n) + 3u) / 4u) * 4u)

// nn_rows.comp: one invocation per row (or element) of a; p.op chooses what it computes.
// a[r] = gelu(layer_norm(a[r]) * b + c) in place through out (b: scale, c: bias); p.quads: rows read four
// floats at a time (cols a multiple of four)
#define NN_ROWS_LAYER_NORM_GELU 0
// out[i][j] = (a[i][j] - b[i]) + (a[i][j] - b[R + j]) + c[S + i] + c[S + R + j], R = rows and S = rows + cols
// each padded to four floats (b: the row and column log-sum-exps, c: the same buffer, the log-sigmoids from
// S); p.quads: four entries per invocation (cols a multiple of four)
#define NN_ROWS_ASSIGNMENT 1
// From a [rows][3 dim] (q, k, v interleaved per channel) and the keypoints b [rows][2] with the rotary
// weights c [2][dim / 2]: out [3][rows][dim] = q and k rotated, v. One invocation per row and channel pair.
#define NN_ROWS_SPLIT_ROTARY 2
// out[out_offset + e] = log sigmoid a[e], the entries from `rows` on shifted to rows padded to four floats:
// the matchability logits' once each, not once per pair.
#define NN_ROWS_LOG_SIGMOID 3
#define NN_ROWS_BINDING_A 0  // A, B and C: R32_SFLOAT texels
#define NN_ROWS_BINDING_B 1
#define NN_ROWS_BINDING_C 2
#define NN_ROWS_BINDING_OUT 3
#define NN_ROWS_BINDING_A4 4  // a and b again, as R32G32B32A32_SFLOAT texels (the quad paths)
#define NN_ROWS_BINDING_B4 5
#define NN_ROWS_BINDING_COUNT 6

struct NnRowsParams {
  uint op;
  uint rows, cols;
  uint count;     // invocations
  float epsilon;  // the layer norm's
  uint quads;     // the layer norm's and the assignment's four-float paths
  uint out_offset;
};

// nn_softmax.comp: for each line l < lines (a row or a column of a), its `line_length` values
// a[l line_step + t step]: out[out_offset + l out_stride + t] = their softmax (NN_SOFTMAX_SOFTMAX), or
// out[out_offset + l] = their log-sum-exp (NN_SOFTMAX_LOG_SUM_EXP). p.path: one invocation per line read
// one float at a time (NN_SOFTMAX_FLOATS), per row read as four-float texels (NN_SOFTMAX_ROW_QUADS: line_step
// a multiple of four), or per four neighbouring columns (NN_SOFTMAX_COLUMN_QUADS: step a multiple of four).
#define NN_SOFTMAX_SOFTMAX 0
#define NN_SOFTMAX_LOG_SUM_EXP 1
#define NN_SOFTMAX_FLOATS 0
#define NN_SOFTMAX_ROW_QUADS 1
#define NN_SOFTMAX_COLUMN_QUADS 2
#define NN_SOFTMAX_BINDING_A 0  // R32_SFLOAT texels
#define NN_SOFTMAX_BINDING_OUT 1
#define NN_SOFTMAX_BINDING_A4 2  // a again, as R32G32B32A32_SFLOAT texels (the quad layouts)
#define NN_SOFTMAX_BINDING_COUNT 3

struct NnSoftmaxParams {
  uint op;
  uint lines, line_length;
  uint line_step, step;  // in floats: rows (a's row stride, 1), columns (1, a's row stride)
  uint out_offset;
  uint out_stride;  // floats from one line's softmax to the next (>= line_length)
  uint path;        // NN_SOFTMAX_FLOATS, _ROW_QUADS or _COLUMN_QUADS
  uint count;       // invocations: lines, or ceil(lines / 4) for column quads
};

#ifdef __cplusplus
}  // namespace litgs::kernels
#endif
#endif
