// The network kernels' shared contract (C++ and GLSL): bindings and parameters. Feature maps are float
// [channels][height][width]; weights are ONNX Conv's [out][in][k][k] and a bias per output channel.
#ifndef LITGS_KERNELS_NN_SHARED_H
#define LITGS_KERNELS_NN_SHARED_H

#ifdef __cplusplus
#include <cstdint>
namespace litgs::kernels {
using uint = uint32_t;
#endif

// ---- nn_conv2d.comp: one invocation per output element (channel, row, column) ----
#define NN_CONV_BINDING_IN 0      // [C_in][H_in][W_in]
#define NN_CONV_BINDING_WEIGHT 1  // [C_out][C_in][k][k]
#define NN_CONV_BINDING_BIAS 2    // [C_out]
#define NN_CONV_BINDING_OUT 3     // [C_out][H_out][W_out] (out)
#define NN_CONV_BINDING_COUNT 4

struct NnConvParams {
  uint in_channels, in_height, in_width;
  uint out_channels, out_height, out_width;
  uint kernel, stride, pad;
  uint relu;   // 1: max(0, x) on the output
  uint count;  // out_channels * out_height * out_width
};

#ifdef __cplusplus
}  // namespace litgs::kernels
#endif
#endif
