#include "host/nn/lighterglue_weights.h"

#include <string>

#include "io/error.h"

namespace litgs::host::nn {
namespace {

using kernels::nn::FeedForwardWeights;
using kernels::nn::LayerNormWeights;
using kernels::nn::LinearWeights;

const io::OnnxNode& node(const io::OnnxModel& model, const std::string& name, const char* op) {
  for (const io::OnnxNode& n : model.nodes)
    if (n.name == name) {
      if (n.op_type != op)
        io::fail(model.file, 0, "node '" + name + "' is " + n.op_type + ", not " + op + ": not LighterGlue");
      return n;
    }
  io::fail(model.file, 0, "no node '" + name + "': not the LighterGlue model");
}

// The MatMul `prefix`/MatMul's weight (its initializer operand) and, with a bias, `prefix`/Add's.
LinearWeights linear(const io::OnnxModel& model, const std::string& prefix, uint32_t in, uint32_t out,
                     bool bias = true) {
  const io::OnnxNode& mm = node(model, prefix + "/MatMul", "MatMul");
  if (mm.inputs.size() != 2 || !model.initializers.count(mm.inputs[1]))
    io::fail(model.file, 0, "'" + mm.name + "' has no weight operand");
  const io::OnnxTensor& w = model.initializer(mm.inputs[1]);
  if (w.dims.size() != 2 || w.dims[0] != in || w.dims[1] != out || w.floats.size() != size_t{in} * out)
    io::fail(model.file, 0,
             "'" + mm.name + "': weight not " + std::to_string(in) + " x " + std::to_string(out) + " floats");
  LinearWeights l{in, out, w.floats, {}};
  if (bias) {
    const io::OnnxNode& add = node(model, prefix + "/Add", "Add");
    const std::string& name = model.initializers.count(add.inputs.at(0)) ? add.inputs[0] : add.inputs.at(1);
    const io::OnnxTensor& b = model.initializer(name);
    if (b.floats.size() != out)
      io::fail(model.file, 0, "'" + add.name + "': bias not " + std::to_string(out));
    l.bias = b.floats;
  }
  return l;
}

FeedForwardWeights feed_forward(const io::OnnxModel& model, const std::string& prefix, uint32_t dim) {
  FeedForwardWeights f;
  f.expand = linear(model, prefix + "/ffn.0", 2 * dim, 2 * dim);
  const io::OnnxNode& ln = node(model, prefix + "/ffn.1/LayerNormalization", "LayerNormalization");
  if (ln.inputs.size() != 3) io::fail(model.file, 0, "'" + ln.name + "': expected a scale and a bias");
  f.norm.scale = model.initializer(ln.inputs[1]).floats;
  f.norm.bias = model.initializer(ln.inputs[2]).floats;
  if (f.norm.scale.size() != 2 * dim || f.norm.bias.size() != 2 * dim)
    io::fail(model.file, 0, "'" + ln.name + "': scale or bias not " + std::to_string(2 * dim));
  if (const io::OnnxAttribute* a = ln.attribute("axis"); a && !a->ints.empty() && a->ints[0] != -1)
    io::fail(model.file, 0, "'" + ln.name + "': not over the last axis");
  if (const io::OnnxAttribute* a = ln.attribute("epsilon"); a && !a->floats.empty())
    f.norm.epsilon = a->floats[0];
  f.project = linear(model, prefix + "/ffn.3", 2 * dim, dim);
  return f;
}

}  // namespace

kernels::nn::LighterGlueWeights lighterglue_weights(const io::OnnxModel& model) {
  constexpr uint32_t kDescriptor = 64, kDim = 96;
  kernels::nn::LighterGlueWeights w;
  w.input_projection = linear(model, "/net/input_proj", kDescriptor, kDim);
  w.position = linear(model, "/net/posenc/Wr", 2, kDim / 2, false).weight;
  // One head: the query/key/value reshape is [1, -1, heads, dim, 3].
  const io::OnnxNode& reshape = node(model, "/net/transformers.0/self_attn/Reshape", "Reshape");
  const io::OnnxTensor& shape = model.initializer(reshape.inputs.at(1));
  if (shape.ints.size() != 5 || shape.ints[2] != 1 || shape.ints[3] != kDim || shape.ints[4] != 3)
    io::fail(model.file, 0, "'" + reshape.name + "': not one head of " + std::to_string(kDim));
  for (int l = 0;; ++l) {
    const std::string layer = "/net/transformers." + std::to_string(l);
    bool present = false;
    for (const io::OnnxNode& n : model.nodes) present = present || n.name == layer + "/self_attn/Wqkv/MatMul";
    if (!present) break;
    kernels::nn::LighterGlueWeights::Layer L;
    L.qkv = linear(model, layer + "/self_attn/Wqkv", kDim, 3 * kDim);
    L.self_out = linear(model, layer + "/self_attn/out_proj", kDim, kDim);
    L.self_ffn = feed_forward(model, layer + "/self_attn/ffn", kDim);
    L.cross_qk = linear(model, layer + "/cross_attn/to_qk", kDim, kDim);
    L.cross_v = linear(model, layer + "/cross_attn/to_v", kDim, kDim);
    L.cross_out = linear(model, layer + "/cross_attn/to_out", kDim, kDim);
    L.cross_ffn = feed_forward(model, layer + "/cross_attn/ffn", kDim);
    w.layers.push_back(std::move(L));
  }
  if (w.layers.empty()) io::fail(model.file, 0, "no transformer layer: not the LighterGlue model");
  const std::string head = "/net/log_assignment." + std::to_string(w.layers.size() - 1);
  w.final_projection = linear(model, head + "/final_proj", kDim, kDim);
  w.matchability = linear(model, head + "/matchability", kDim, 1);
  return w;
}

}  // namespace litgs::host::nn
