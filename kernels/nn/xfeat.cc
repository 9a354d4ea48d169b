#include "kernels/nn/xfeat.h"

#include <stdexcept>
#include <string>

#include "engine/sequence.h"
#include "kernels/nn/nn_shared.h"

namespace litgs::kernels {
namespace {

// A feature map of the forward pass: its array lives in the pass's pool until the sequence has run.
struct Map {
  engine::DeviceArray<float>* data = nullptr;
  MapShape shape;
  const engine::Buffer& buffer() const { return data->buffer(); }
};

}  // namespace

struct XfeatNetwork::Pass {
  explicit Pass(engine::Context& c) : context(c), sequence(c) {}
  engine::Context& context;
  engine::Sequence sequence;
  std::vector<std::unique_ptr<engine::DeviceArray<float>>> pool;  // every map, alive until the pass ends
  Map features, keypoints, heatmap;
  Map make(const MapShape& shape, const char* name = "xfeat: feature map") {
    pool.push_back(std::make_unique<engine::DeviceArray<float>>(context, name, shape.elements()));
    return Map{pool.back().get(), shape};
  }
};

XfeatNetwork::XfeatNetwork(engine::Context& context, const nn::XfeatWeights& weights)
    : context_(&context), conv_(context), map_(context), keypoints_(context) {
  if (weights.convs.size() != 27)
    throw std::invalid_argument("XfeatNetwork: " + std::to_string(weights.convs.size()) +
                                " convolutions, XFeat has 27");
  for (const nn::ConvWeights& c : weights.convs) {
    Layer l;
    const std::vector<float> packed = pack_conv_weights(c.weight, c.out_channels, c.in_channels, c.kernel);
    l.weight = std::make_unique<engine::DeviceArray<float>>(context, "xfeat: weight", packed.size());
    l.bias = std::make_unique<engine::DeviceArray<float>>(context, "xfeat: bias", c.bias.size());
    l.weight->upload(packed);
    l.bias->upload(c.bias);
    l.out_channels = c.out_channels;
    l.in_channels = c.in_channels;
    l.kernel = c.kernel;
    l.stride = c.stride;
    l.pad = c.pad;
    layers_.push_back(std::move(l));
  }
}

XfeatNetwork::~XfeatNetwork() = default;

void XfeatNetwork::forward(Pass& pass, const std::vector<float>& image, uint32_t height,
                           uint32_t width) const {
  if (!height || !width || height % 32 || width % 32 || image.size() != size_t{height} * width)
    throw std::invalid_argument(
        "XfeatNetwork: a one-channel image whose sides are positive multiples of 32, not " +
        std::to_string(width) + "x" + std::to_string(height) + " with " + std::to_string(image.size()) +
        " values");
  engine::Sequence& s = pass.sequence;
  const auto make = [&pass](const MapShape& shape) { return pass.make(shape); };
  // Layers first .. first + count - 1 in turn: ReLU after each but the last, `last` after the last, and
  // `residual` (a map of the last one's shape) added as the last one writes.
  const auto layers = [&](const Map& in, size_t first, size_t count, uint32_t last,
                          const Map* residual = nullptr) {
    Map x = in;
    for (size_t i = first; i < first + count; ++i) {
      const Layer& l = layers_[i];
      const ConvShape c{x.shape.channels,
                        x.shape.height,
                        x.shape.width,
                        l.out_channels,
                        l.kernel,
                        l.stride,
                        l.pad,
                        i + 1 < first + count ? uint32_t{NN_ACTIVATION_RELU} : last};
      const Map y = make({c.out_channels, c.out_height(), c.out_width()});
      const bool add = residual && i + 1 == first + count;
      if (add && (residual->shape.channels != y.shape.channels || residual->shape.height != y.shape.height ||
                  residual->shape.width != y.shape.width))
        throw std::logic_error("XfeatNetwork: a residual map whose shape differs from its layer's output");
      conv_.record(s, x.buffer(), l.weight->buffer(), l.bias->buffer(), y.buffer(), c,
                   add ? &residual->buffer() : nullptr);
      x = y;
    }
    return x;
  };
  const Map input = make({1, height, width});
  input.data->upload(image);
  // The dataflow and the layer indices of kernels/nn/xfeat_reference.cc (XfeatReference::run).
  const Map x1 = layers(input, 0, 4, NN_ACTIVATION_RELU);
  const Map pooled = make({1, height / 4, width / 4});
  map_.average_pool(s, input.buffer(), pooled.buffer(), input.shape, 4);
  // The skip branch's 1x1 convolution adds x1 as it writes (x1 + skip: the reference's add, commuted).
  const Map sum1 = layers(pooled, 4, 1, NN_ACTIVATION_NONE, &x1);
  const Map x2 = layers(sum1, 5, 2, NN_ACTIVATION_RELU);
  const Map x3 = layers(x2, 7, 3, NN_ACTIVATION_RELU);
  const Map x4 = layers(x3, 10, 3, NN_ACTIVATION_RELU);
  const Map x5 = layers(x4, 13, 4, NN_ACTIVATION_RELU);
  // (x3 + resize(x4)) + resize(x5), the upsampled maps never written.
  const Map fused34 = make(x3.shape), fused = make(x3.shape);
  map_.add_resized(s, x4.buffer(), x3.buffer(), fused34.buffer(), x4.shape, x3.shape);
  map_.add_resized(s, x5.buffer(), fused34.buffer(), fused.buffer(), x5.shape, x3.shape);
  pass.features = layers(fused, 17, 3, NN_ACTIVATION_NONE);
  pass.heatmap = layers(pass.features, 20, 3, NN_ACTIVATION_SIGMOID);
  const Map cells = make({64, height / 8, width / 8});
  map_.unfold(s, input.buffer(), cells.buffer(), input.shape, 8);
  pass.keypoints = layers(cells, 23, 4, NN_ACTIVATION_NONE);
}

XfeatDeviceOutputs XfeatNetwork::run(const std::vector<float>& image, uint32_t height, uint32_t width) const {
  Pass pass(*context_);
  forward(pass, image, height, width);
  pass.sequence.submit_and_wait();
  XfeatDeviceOutputs out;
  out.height = pass.features.shape.height;
  out.width = pass.features.shape.width;
  out.features = pass.features.data->download();
  out.keypoints = pass.keypoints.data->download();
  out.heatmap = pass.heatmap.data->download();
  out.kernel_times = pass.sequence.profile();
  return out;
}

XfeatDetections XfeatNetwork::detect(const std::vector<float>& image, uint32_t height, uint32_t width,
                                     const nn::XfeatKeypointOptions& o,
                                     const KeypointSelection& select) const {
  Pass pass(*context_);
  forward(pass, image, height, width);
  const uint32_t h = height / 8, w = width / 8;
  const Map heat = pass.make({1, height, width}), scores = pass.make({1, height, width});
  const Map normalized = pass.make(pass.features.shape);
  keypoints_.heatmap(pass.sequence, pass.keypoints.buffer(), heat.buffer(), h, w);
  keypoints_.scores(pass.sequence, heat.buffer(), pass.heatmap.buffer(), scores.buffer(), h, w,
                    static_cast<float>(o.threshold), static_cast<uint32_t>(o.nms_window));
  keypoints_.normalize(pass.sequence, pass.features.buffer(), normalized.buffer(), pass.features.shape);
  pass.sequence.submit_and_wait();
  XfeatDetections out;
  out.height = height;
  out.width = width;
  out.keypoints = nn::top_keypoints(scores.data->download(), int(width), int(height), o.top_k);
  if (select) {
    std::vector<nn::ScoredKeypoint> chosen;
    for (size_t i : select(out.keypoints)) {
      if (i >= out.keypoints.size())
        throw std::out_of_range("XfeatNetwork::detect: the selection names keypoint " + std::to_string(i) +
                                " of " + std::to_string(out.keypoints.size()));
      chosen.push_back(out.keypoints[i]);
    }
    out.keypoints = std::move(chosen);
  }
  if (out.keypoints.empty()) return out;
  // The top-k choice is on the host: a second sequence samples the descriptors at the chosen pixels.
  std::vector<float> xy;
  for (const nn::ScoredKeypoint& k : out.keypoints) xy.insert(xy.end(), {k.x, k.y});
  engine::DeviceArray<float> positions(*context_, "xfeat: keypoints", xy.size());
  positions.upload(xy);
  engine::DeviceArray<float> descriptors(*context_, "xfeat: descriptors",
                                         out.keypoints.size() * pass.features.shape.channels);
  engine::Sequence s(*context_);
  keypoints_.descriptors(s, normalized.buffer(), positions.buffer(), descriptors.buffer(),
                         pass.features.shape, static_cast<uint32_t>(out.keypoints.size()));
  s.submit_and_wait();
  out.descriptors = descriptors.download();
  return out;
}

}  // namespace litgs::kernels
