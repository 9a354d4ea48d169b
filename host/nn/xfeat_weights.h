// XFeat's weights from its ONNX model (kernels/nn/models/xfeat/): the 27 convolutions in the exported
// graph's order, each checked to sit where XFeat has one (its module's name prefix), with group 1 and one
// stride and padding on both axes.
#pragma once

#include "io/onnx_model.h"
#include "kernels/nn/nn_weights.h"

namespace litgs::host::nn {

// io::IoError naming the model file and what does not fit XFeat.
kernels::nn::XfeatWeights xfeat_weights(const io::OnnxModel& model);

}  // namespace litgs::host::nn
