// The network kernels (kernels/nn/) against their double-precision CPU references (kernels/nn/nn_reference.h,
// xfeat_reference.h), validation layer on: each of XFeat's convolutions with its own weights (3x3 and 1x1,
// strides 1 and 2, with and without ReLU) on inputs whose width is or is not a multiple of four, the whole
// network, and bad shapes. Tolerances (float against double): a convolution within 1e-5 of its largest
// output; the network's outputs within 1e-4 of each output's RMS, element by element.
#include <gtest/gtest.h>

#include <cmath>
#include <random>
#include <vector>

#include "engine/buffer.h"
#include "engine/sequence.h"
#include "gpu_test.h"
#include "host/nn/xfeat_weights.h"
#include "io/onnx_model.h"
#include "kernels/nn/nn_conv.h"
#include "kernels/nn/nn_reference.h"
#include "kernels/nn/nn_shared.h"
#include "kernels/nn/xfeat.h"
#include "kernels/nn/xfeat_reference.h"

namespace litgs {
namespace {

using engine::DeviceArray;
using kernels::nn::FeatureMap;

kernels::nn::XfeatWeights xfeat_weights() {
  return host::nn::xfeat_weights(
      io::read_onnx_model(std::string(LITGS_NN_MODELS) + "/xfeat/xfeat_640x640.onnx"));
}

FeatureMap random_map(int c, int h, int w, uint32_t seed) {
  std::mt19937 rng(seed);
  std::normal_distribution<float> n(0.0f, 1.0f);
  FeatureMap m(c, h, w);
  for (double& v : m.values) v = n(rng);  // float values, as the device holds them
  return m;
}

class NnConvTest : public testing::GpuTest {
 protected:
  // conv(in) on the device and on the CPU; the largest difference over the largest reference magnitude.
  double relative_error(const FeatureMap& in, const kernels::nn::ConvWeights& w, bool relu) {
    FeatureMap ref = kernels::nn::conv2d(in, w);
    if (relu) kernels::nn::relu(ref);
    kernels::ConvShape shape{uint32_t(in.channels),
                             uint32_t(in.height),
                             uint32_t(in.width),
                             w.out_channels,
                             w.kernel,
                             w.stride,
                             w.pad,
                             relu ? uint32_t{NN_ACTIVATION_RELU} : uint32_t{NN_ACTIVATION_NONE}};
    const std::vector<float> input(in.values.begin(), in.values.end());
    const std::vector<float> packed =
        kernels::pack_conv_weights(w.weight, w.out_channels, w.in_channels, w.kernel);
    DeviceArray<float> x(context(), "test: in", input.size()),
        weight(context(), "test: weight", packed.size()), bias(context(), "test: bias", w.bias.size()),
        y(context(), "test: out", shape.out_elements());
    x.upload(input);
    weight.upload(packed);
    bias.upload(w.bias);
    kernels::Conv2dKernel conv(context());
    engine::Sequence s(context());
    conv.record(s, x.buffer(), weight.buffer(), bias.buffer(), y.buffer(), shape);
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

TEST_F(NnConvTest, XfeatLayersMatchTheReference) {
  const kernels::nn::XfeatWeights weights = xfeat_weights();
  ASSERT_EQ(weights.convs.size(), 27u);
  uint32_t seed = 0;
  for (const kernels::nn::ConvWeights& w : weights.convs) {
    // 29 wide: neither the stride nor the kernel's tile of NN_CONV_PIXELS divides it (a partial tile, the
    // generic path). 40 and 8 wide: rows of four-float texels (the 1x1 and 3x3 paths), with a partial run
    // of NN_CONV_RUN pixels and, at 8, a row of two texels whose both ends are padding.
    for (int width : {29, 40, 8}) {
      const FeatureMap in = random_map(int(w.in_channels), 36, width, seed++);
      for (bool relu : {false, true})
        EXPECT_LT(relative_error(in, w, relu), 1e-5)
            << "layer " << &w - weights.convs.data() << ", " << width << " wide";
    }
  }
}

TEST_F(NnConvTest, BadShapesAndShortBuffersAreRefused) {
  kernels::Conv2dKernel conv(context());
  DeviceArray<float> small(context(), "test: small", 4);
  engine::Sequence s(context());
  kernels::ConvShape shape{1, 8, 8, 2, 3, 1, 1, NN_ACTIVATION_NONE};
  EXPECT_THROW(conv.record(s, small.buffer(), small.buffer(), small.buffer(), small.buffer(), shape),
               std::invalid_argument);
  kernels::ConvShape zero_stride = shape;
  zero_stride.stride = 0;
  EXPECT_THROW(zero_stride.check(), std::invalid_argument);
  kernels::ConvShape too_large{1, 2, 2, 1, 5, 1, 0, NN_ACTIVATION_NONE};
  EXPECT_THROW(too_large.check(), std::invalid_argument);
  // Weights of another shape than the one named, and unpacked weights where the packed ones are longer.
  EXPECT_THROW(kernels::pack_conv_weights(std::vector<float>(17), 2, 1, 3), std::invalid_argument);
  DeviceArray<float> unpacked(context(), "test: unpacked", 2 * 9), input(context(), "test: in", 64),
      out(context(), "test: out", 2 * 64), bias(context(), "test: bias", 2);
  EXPECT_THROW(conv.record(s, input.buffer(), unpacked.buffer(), bias.buffer(), out.buffer(), shape),
               std::invalid_argument);
  kernels::MapKernel map(context());
  EXPECT_THROW(map.unfold(s, small.buffer(), small.buffer(), {2, 8, 8}, 8), std::invalid_argument);
}

// The whole network on the device against the CPU reference on a 96x64 random image (not square, 3 x 2
// cells of 32), and the hard cases: a uniform image and the smallest size give finite outputs, a size that
// is not a multiple of 32 is refused.
TEST_F(NnConvTest, XfeatNetworkMatchesTheReference) {
  const kernels::nn::XfeatWeights weights = xfeat_weights();
  const kernels::nn::XfeatReference reference(weights);
  const kernels::XfeatNetwork network(context(), weights);
  FeatureMap image = random_map(1, 64, 96, 7);
  const kernels::nn::XfeatOutputs ref = reference.run(image);
  const std::vector<float> pixels(image.values.begin(), image.values.end());
  const kernels::XfeatDeviceOutputs out = network.run(pixels, 64, 96);
  ASSERT_EQ(out.height, 8u);
  ASSERT_EQ(out.width, 12u);
  const std::pair<const std::vector<float>*, const FeatureMap*> pairs[] = {
      {&out.features, &ref.features}, {&out.keypoints, &ref.keypoints}, {&out.heatmap, &ref.heatmap}};
  for (const auto& [device, cpu] : pairs) {
    ASSERT_EQ(device->size(), cpu->values.size());
    double rms = 0, worst = 0;
    for (double v : cpu->values) rms += v * v;
    rms = std::sqrt(rms / double(cpu->values.size()));
    for (size_t i = 0; i < device->size(); ++i)
      worst = std::max(worst, std::abs((*device)[i] - cpu->values[i]));
    EXPECT_LT(worst, 1e-4 * rms) << "channels " << cpu->channels << ": worst " << worst << ", rms " << rms;
  }
  const kernels::XfeatDeviceOutputs uniform = network.run(std::vector<float>(32 * 32, 0.0f), 32, 32);
  for (const auto* v : {&uniform.features, &uniform.keypoints, &uniform.heatmap})
    for (float x : *v) ASSERT_TRUE(std::isfinite(x));
  EXPECT_THROW(network.run(std::vector<float>(40 * 32, 0.0f), 40, 32), std::invalid_argument);
}

}  // namespace
}  // namespace litgs
