// The network kernels (kernels/nn/) against their double-precision CPU references (kernels/nn/nn_reference.h,
// xfeat_reference.h), validation layer on: each of XFeat's convolutions with its own weights (3x3 and 1x1,
// strides 1 and 2, with and without ReLU, with a residual add) on inputs whose width is or is not a multiple
// of four, the feature-map operations, the whole network, and bad shapes. Tolerances (float against double):
// a convolution within 1e-5 of its largest output, a map operation within 1e-6; the network's outputs within
// 1e-4 of each output's RMS, element by element.
#include <gtest/gtest.h>

#include <cmath>
#include <memory>
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
  // conv(in) (+ residual) on the device and on the CPU; the largest difference over the largest reference
  // magnitude.
  double relative_error(const FeatureMap& in, const kernels::nn::ConvWeights& w, bool relu,
                        const FeatureMap* residual = nullptr) {
    FeatureMap ref = kernels::nn::conv2d(in, w);
    if (relu) kernels::nn::relu(ref);
    if (residual) ref = kernels::nn::add(ref, *residual);
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
    DeviceArray<float> r(context(), "test: residual", residual ? residual->values.size() : 1);
    if (residual) r.upload(std::vector<float>(residual->values.begin(), residual->values.end()));
    kernels::Conv2dKernel conv(context());
    engine::Sequence s(context());
    conv.record(s, x.buffer(), weight.buffer(), bias.buffer(), y.buffer(), shape,
                residual ? &r.buffer() : nullptr);
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

// A residual map added as the convolution writes (XFeat's skip branch; a ReLU layer too, where the add
// must follow the activation), on the generic path (29 wide) and the row paths (40 wide).
TEST_F(NnConvTest, ResidualIsAddedAfterTheActivation) {
  const kernels::nn::XfeatWeights weights = xfeat_weights();
  uint32_t seed = 100;
  for (size_t layer : {size_t{4}, size_t{1}})
    for (int width : {29, 40}) {
      const kernels::nn::ConvWeights& w = weights.convs[layer];
      const FeatureMap in = random_map(int(w.in_channels), 20, width, seed++);
      const FeatureMap shape_of_out = kernels::nn::conv2d(in, w);
      const FeatureMap residual =
          random_map(shape_of_out.channels, shape_of_out.height, shape_of_out.width, seed++);
      EXPECT_LT(relative_error(in, w, layer == 1, &residual), 1e-5) << "layer " << layer << ", " << width;
    }
}

// The feature-map operations (nn_map.comp) against their references: add, average pool, bilinear resize up
// and down (shapes that no factor divides), the add of a resized map, unfold.
TEST_F(NnConvTest, MapOperationsMatchTheReference) {
  kernels::MapKernel map(context());
  const auto upload = [&](const FeatureMap& m) {
    auto a = std::make_unique<DeviceArray<float>>(context(), "test: map", m.values.size());
    a->upload(std::vector<float>(m.values.begin(), m.values.end()));
    return a;
  };
  const auto shape_of = [](const FeatureMap& m) {
    return kernels::MapShape{uint32_t(m.channels), uint32_t(m.height), uint32_t(m.width)};
  };
  const auto worst_relative = [](const std::vector<float>& out, const FeatureMap& ref) {
    EXPECT_EQ(out.size(), ref.values.size());
    double worst = 0, largest = 1e-12;
    for (size_t i = 0; i < out.size() && i < ref.values.size(); ++i) {
      worst = std::max(worst, std::abs(double(out[i]) - ref.values[i]));
      largest = std::max(largest, std::abs(ref.values[i]));
    }
    return worst / largest;
  };
  const FeatureMap a = random_map(3, 12, 20, 1), b = random_map(3, 12, 20, 2);
  const FeatureMap small = random_map(3, 5, 7, 3), image = random_map(1, 16, 24, 4);
  const auto da = upload(a), db = upload(b), dsmall = upload(small), dimage = upload(image);
  DeviceArray<float> sum(context(), "test: sum", a.values.size()), up(context(), "test: up", a.values.size()),
      up_added(context(), "test: added", a.values.size()), down(context(), "test: down", 3 * 5 * 7),
      pooled(context(), "test: pooled", 3 * 3 * 5), cells(context(), "test: cells", 16 * 4 * 6);
  engine::Sequence s(context());
  map.add(s, da->buffer(), db->buffer(), sum.buffer(), shape_of(a));
  map.resize(s, dsmall->buffer(), up.buffer(), shape_of(small), 12, 20);
  map.add_resized(s, dsmall->buffer(), db->buffer(), up_added.buffer(), shape_of(small), shape_of(b));
  map.resize(s, da->buffer(), down.buffer(), shape_of(a), 5, 7);
  map.average_pool(s, da->buffer(), pooled.buffer(), shape_of(a), 4);
  map.unfold(s, dimage->buffer(), cells.buffer(), shape_of(image), 4);
  s.submit_and_wait();
  const FeatureMap upsampled = kernels::nn::resize_bilinear(small, 12, 20);
  EXPECT_LT(worst_relative(sum.download(), kernels::nn::add(a, b)), 1e-6);
  EXPECT_LT(worst_relative(up.download(), upsampled), 1e-6);
  EXPECT_LT(worst_relative(up_added.download(), kernels::nn::add(b, upsampled)), 1e-6);
  EXPECT_LT(worst_relative(down.download(), kernels::nn::resize_bilinear(a, 5, 7)), 1e-6);
  EXPECT_LT(worst_relative(pooled.download(), kernels::nn::average_pool(a, 4, 4)), 1e-6);
  EXPECT_LT(worst_relative(cells.download(), kernels::nn::unfold(image, 4)), 1e-6);
  // A resized map whose channels differ from the map it is added to.
  EXPECT_THROW(map.add_resized(s, dsmall->buffer(), db->buffer(), up_added.buffer(), {2, 5, 7}, shape_of(b)),
               std::invalid_argument);
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
