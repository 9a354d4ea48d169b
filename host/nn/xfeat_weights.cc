#include "host/nn/xfeat_weights.h"

#include <iterator>
#include <string>

#include "io/error.h"

namespace litgs::host::nn {
namespace {

// XFeat's modules in the exported graph's order and how many convolutions each has.
struct Module {
  const char* prefix;
  size_t convs;
};
constexpr Module kModules[] = {{"/block1/", 4},       {"/skip1/", 1},        {"/block2/", 2},
                               {"/block3/", 3},       {"/block4/", 3},       {"/block5/", 4},
                               {"/block_fusion/", 3}, {"/heatmap_head/", 3}, {"/keypoint_head/", 4}};

uint32_t single(const io::OnnxNode& n, const char* attribute, uint32_t fallback, const io::OnnxModel& model) {
  const io::OnnxAttribute* a = n.attribute(attribute);
  if (!a || a->ints.empty()) return fallback;
  for (int64_t v : a->ints)
    if (v != a->ints[0] || v < 0)
      io::fail(model.file, 0, "Conv '" + n.name + "': " + attribute + " differ between axes: not XFeat's");
  return static_cast<uint32_t>(a->ints[0]);
}

}  // namespace

kernels::nn::XfeatWeights xfeat_weights(const io::OnnxModel& model) {
  kernels::nn::XfeatWeights out;
  size_t module = 0, in_module = 0;
  for (const io::OnnxNode& n : model.nodes) {
    if (n.op_type != "Conv") continue;
    while (module < std::size(kModules) && in_module == kModules[module].convs) ++module, in_module = 0;
    if (module == std::size(kModules) || n.name.rfind(kModules[module].prefix, 0) != 0)
      io::fail(model.file, 0,
               "Conv '" + n.name + "' is not where XFeat has one (expected " +
                   (module < std::size(kModules) ? std::string(kModules[module].prefix) : "no more") +
                   "): not the XFeat model");
    if (n.inputs.size() != 3 || single(n, "group", 1, model) != 1)
      io::fail(model.file, 0, "Conv '" + n.name + "': expected a weight, a bias and group 1");
    const io::OnnxTensor& w = model.initializer(n.inputs[1]);
    const io::OnnxTensor& b = model.initializer(n.inputs[2]);
    if (w.dims.size() != 4 || w.dims[2] != w.dims[3] || w.floats.empty() ||
        b.floats.size() != static_cast<size_t>(w.dims[0]))
      io::fail(model.file, 0, "Conv '" + n.name + "': weight or bias of the wrong shape or type");
    kernels::nn::ConvWeights c;
    c.out_channels = static_cast<uint32_t>(w.dims[0]);
    c.in_channels = static_cast<uint32_t>(w.dims[1]);
    c.kernel = static_cast<uint32_t>(w.dims[2]);
    c.weight = w.floats;
    c.bias = b.floats;
    c.stride = single(n, "strides", 1, model);
    c.pad = single(n, "pads", 0, model);
    out.convs.push_back(std::move(c));
    ++in_module;
  }
  size_t expected = 0;
  for (const Module& m : kModules) expected += m.convs;
  if (out.convs.size() != expected)
    io::fail(model.file, 0,
             std::to_string(out.convs.size()) + " convolutions, XFeat has " + std::to_string(expected));
  return out;
}

}  // namespace litgs::host::nn
