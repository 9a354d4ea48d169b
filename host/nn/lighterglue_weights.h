// LighterGlue's weights from its ONNX model (kernels/nn/models/lighterglue/): every MatMul, bias and layer
// norm found by the node names of the exported graph (/net/input_proj, /net/transformers.N/...,
// /net/log_assignment.N/...), each checked against the shapes of one head of width 96 over 64-d descriptors.
#pragma once

#include "io/onnx_model.h"
#include "kernels/nn/nn_weights.h"

namespace litgs::host::nn {

// io::IoError naming the model file and the node or weight that does not fit LighterGlue.
kernels::nn::LighterGlueWeights lighterglue_weights(const io::OnnxModel& model);

}  // namespace litgs::host::nn
