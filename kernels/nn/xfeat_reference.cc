#include "kernels/nn/xfeat_reference.h"

#include <stdexcept>
#include <string>
#include <utility>

#include "io/error.h"

namespace litgs::kernels::nn {
namespace {

// XFeat's convolutions in the exported graph's order: the module each belongs to and how many it has.
struct Stage {
  const char* name;
  size_t convs;
};
constexpr Stage kStages[] = {{"/block1/", 4},       {"/skip1/", 1},        {"/block2/", 2},
                             {"/block3/", 3},       {"/block4/", 3},       {"/block5/", 4},
                             {"/block_fusion/", 3}, {"/heatmap_head/", 3}, {"/keypoint_head/", 4}};

int single(const io::OnnxNode& n, const char* attribute, const io::OnnxModel& model) {
  const io::OnnxAttribute* a = n.attribute(attribute);
  if (!a || a->ints.empty()) return attribute[0] == 's' ? 1 : 0;  // strides default 1, pads 0
  for (int64_t v : a->ints)
    if (v != a->ints[0])
      io::fail(model.file, 0, "Conv '" + n.name + "': unequal " + attribute + " are not XFeat's");
  return static_cast<int>(a->ints[0]);
}

}  // namespace

XfeatReference::XfeatReference(io::OnnxModel model_in) : model_(std::move(model_in)) {
  const io::OnnxModel& model = model_;
  size_t stage = 0, in_stage = 0;
  for (const io::OnnxNode& n : model.nodes) {
    if (n.op_type != "Conv") continue;
    while (stage < std::size(kStages) && in_stage == kStages[stage].convs) ++stage, in_stage = 0;
    if (stage == std::size(kStages) || n.name.rfind(kStages[stage].name, 0) != 0)
      io::fail(model.file, 0,
               "Conv '" + n.name + "' is not where XFeat has one (expected " +
                   (stage < std::size(kStages) ? std::string(kStages[stage].name) : "no more") +
                   "): not the XFeat model");
    const io::OnnxAttribute* group = n.attribute("group");
    if (n.inputs.size() != 3 || (group && !group->ints.empty() && group->ints[0] != 1))
      io::fail(model.file, 0, "Conv '" + n.name + "': expected weight, bias and group 1");
    convs_.push_back({&model.initializer(n.inputs[1]), &model.initializer(n.inputs[2]),
                      single(n, "strides", model), single(n, "pads", model)});
    ++in_stage;
  }
  size_t expected = 0;
  for (const Stage& s : kStages) expected += s.convs;
  if (convs_.size() != expected)
    io::fail(model.file, 0,
             std::to_string(convs_.size()) + " convolutions, XFeat has " + std::to_string(expected));
}

FeatureMap XfeatReference::apply(const FeatureMap& in, size_t first, size_t count, bool relu_last) const {
  FeatureMap x = in;
  for (size_t i = first; i < first + count; ++i) {
    x = conv2d(x, *convs_[i].weight, *convs_[i].bias, convs_[i].stride, convs_[i].pad);
    if (i + 1 < first + count || relu_last) relu(x);
  }
  return x;
}

XfeatOutputs XfeatReference::run(const FeatureMap& image) const {
  if (image.channels != 1 || image.height <= 0 || image.width <= 0 || image.height % 32 || image.width % 32)
    throw std::invalid_argument("XFeat: a one-channel image whose sides are positive multiples of 32, not " +
                                std::to_string(image.width) + "x" + std::to_string(image.height));
  // Convolution indices of each module, in kStages' order.
  const FeatureMap x1 = apply(image, 0, 4, true);
  const FeatureMap skip = apply(average_pool(image, 4, 4), 4, 1, false);
  const FeatureMap x2 = apply(add(x1, skip), 5, 2, true);
  const FeatureMap x3 = apply(x2, 7, 3, true);
  const FeatureMap x4 = apply(x3, 10, 3, true);
  const FeatureMap x5 = apply(x4, 13, 4, true);
  const FeatureMap fused =
      add(add(x3, resize_bilinear(x4, x3.height, x3.width)), resize_bilinear(x5, x3.height, x3.width));
  XfeatOutputs out;
  out.features = apply(fused, 17, 3, false);
  out.heatmap = apply(out.features, 20, 3, false);
  sigmoid(out.heatmap);
  out.keypoints = apply(unfold(image, 8), 23, 4, false);
  return out;
}

}  // namespace litgs::kernels::nn
