// The network convolution kernel (kernels/nn/nn_conv2d.comp) against its double-precision CPU reference
// (kernels/nn/nn_reference.h), validation layer on: XFeat's own layer shapes and weights (3x3 and 1x1,
// strides 1 and 2, with and without ReLU), a size that is not a multiple of the stride, and bad shapes.
// Tolerance: float sums of up to 128 x 9 products against double, 1e-5 of the output's largest magnitude.
#include <gtest/gtest.h>

#include <cmath>
#include <random>
#include <vector>

#include "engine/buffer.h"
#include "engine/sequence.h"
#include "gpu_test.h"
#include "io/onnx_model.h"
#include "kernels/nn/nn_conv.h"
#include "kernels/nn/nn_reference.h"

namespace litgs {
namespace {

using engine::DeviceArray;

class NnConvTest : public testing::GpuTest {
 protected:
  // conv(in) on the device and on the CPU; the largest difference over the largest reference magnitude.
  double relative_error(const kernels::nn::FeatureMap& in, const io::OnnxTensor& weight,
                        const io::OnnxTensor& bias, uint32_t stride, uint32_t pad, bool relu) {
    kernels::nn::FeatureMap ref = kernels::nn::conv2d(in, weight, bias, int(stride), int(pad));
    if (relu) kernels::nn::relu(ref);
    kernels::ConvShape shape{uint32_t(in.channels),
                             uint32_t(in.height),
                             uint32_t(in.width),
                             uint32_t(weight.dims[0]),
                             uint32_t(weight.dims[2]),
                             stride,
                             pad,
                             relu};
    std::vector<float> input(in.values.begin(), in.values.end());
    DeviceArray<float> x(context(), "test: in", input.size()),
        w(context(), "test: weight", weight.floats.size()), b(context(), "test: bias", bias.floats.size()),
        y(context(), "test: out", shape.out_elements());
    x.upload(input);
    w.upload(weight.floats);
    b.upload(bias.floats);
    kernels::Conv2dKernel conv(context());
    engine::Sequence s(context());
    conv.record(s, x.buffer(), w.buffer(), b.buffer(), y.buffer(), shape);
    s.submit_and_wait();
    const std::vector<float> out = y.download();
    EXPECT_EQ(out.size(), ref.values.size());
    EXPECT_EQ(int(shape.out_height()), ref.height);
    double worst = 0, largest = 1e-12;
    for (size_t i = 0; i < out.size() && i < ref.values.size(); ++i) {
      worst = std::max(worst, std::abs(double(out[i]) - ref.values[i]));
      largest = std::max(largest, std::abs(ref.values[i]));
    }
    return worst / largest;
  }
};

kernels::nn::FeatureMap random_map(int c, int h, int w, uint32_t seed) {
  std::mt19937 rng(seed);
  std::normal_distribution<float> n(0.0f, 1.0f);
  kernels::nn::FeatureMap m(c, h, w);
  for (double& v : m.values) v = n(rng);  // float values, as the device holds them
  return m;
}

TEST_F(NnConvTest, XfeatLayersMatchTheReference) {
  const io::OnnxModel model = io::read_onnx_model(std::string(LITGS_NN_MODELS) + "/xfeat/xfeat_640x640.onnx");
  int checked = 0;
  for (const io::OnnxNode& n : model.nodes) {
    if (n.op_type != "Conv") continue;
    const io::OnnxTensor& w = model.initializer(n.inputs[1]);
    const io::OnnxTensor& b = model.initializer(n.inputs[2]);
    const uint32_t stride = uint32_t(n.attribute("strides")->ints[0]),
                   pad = uint32_t(n.attribute("pads")->ints[0]);
    // 36 x 28 input: not a multiple of the stride on one side.
    const auto in = random_map(int(w.dims[1]), 36, 28, uint32_t(checked));
    for (bool relu : {false, true}) {
      const double e = relative_error(in, w, b, stride, pad, relu);
      EXPECT_LT(e, 1e-5) << n.name << (relu ? " + relu" : "");
    }
    ++checked;
  }
  EXPECT_EQ(checked, 27);
}

TEST_F(NnConvTest, BadShapesAndShortBuffersAreRefused) {
  kernels::Conv2dKernel conv(context());
  DeviceArray<float> small(context(), "test: small", 4);
  engine::Sequence s(context());
  kernels::ConvShape shape{1, 8, 8, 2, 3, 1, 1, false};
  EXPECT_THROW(conv.record(s, small.buffer(), small.buffer(), small.buffer(), small.buffer(), shape),
               std::invalid_argument);
  kernels::ConvShape zero_stride = shape;
  zero_stride.stride = 0;
  EXPECT_THROW(zero_stride.check(), std::invalid_argument);
  kernels::ConvShape too_large{1, 2, 2, 1, 5, 1, 0, false};
  EXPECT_THROW(too_large.check(), std::invalid_argument);
}

}  // namespace
}  // namespace litgs
