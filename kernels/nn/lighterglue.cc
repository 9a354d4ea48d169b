#include "kernels/nn/lighterglue.h"

#include <cmath>
#include <stdexcept>
#include <string>

#include "engine/sequence.h"
#include "kernels/nn/lighterglue_reference.h"

namespace litgs::kernels {
namespace {

using Array = engine::DeviceArray<float>;

std::unique_ptr<Array> array(engine::Context& c, const char* name, const std::vector<float>& values) {
  auto a = std::make_unique<Array>(c, name, values.size());
  a->upload(values);
  return a;
}

}  // namespace

LighterGlueNetwork::Linear LighterGlueNetwork::upload(const nn::LinearWeights& w, const char* name) {
  if (!w.in || !w.out || w.weight.size() != size_t{w.in} * w.out ||
      (!w.bias.empty() && w.bias.size() != w.out))
    throw std::invalid_argument(std::string("LighterGlueNetwork: ") + name + " has the wrong shape");
  Linear l;
  l.in = w.in;
  l.out = w.out;
  l.weight = array(*context_, name, w.weight);
  if (!w.bias.empty()) l.bias = array(*context_, name, w.bias);
  return l;
}

LighterGlueNetwork::FeedForward LighterGlueNetwork::upload(const nn::FeedForwardWeights& f) {
  FeedForward out;
  out.expand = upload(f.expand, "lighterglue: feed-forward expansion");
  out.project = upload(f.project, "lighterglue: feed-forward projection");
  if (f.norm.scale.size() != out.expand.out || f.norm.bias.size() != out.expand.out)
    throw std::invalid_argument("LighterGlueNetwork: a layer norm of the wrong width");
  out.scale = array(*context_, "lighterglue: layer norm scale", f.norm.scale);
  out.shift = array(*context_, "lighterglue: layer norm bias", f.norm.bias);
  out.epsilon = static_cast<float>(f.norm.epsilon);
  return out;
}

LighterGlueNetwork::LighterGlueNetwork(engine::Context& context, const nn::LighterGlueWeights& w)
    : context_(&context), ops_(context), descriptor_width_(w.input_projection.in), dim_(w.dim()) {
  if (w.layers.empty() || dim_ % 2 || w.position.size() != dim_ || w.final_projection.out != dim_ ||
      w.matchability.out != 1)
    throw std::invalid_argument("LighterGlueNetwork: weights without LighterGlue's shapes");
  input_ = upload(w.input_projection, "lighterglue: input projection");
  final_ = upload(w.final_projection, "lighterglue: final projection");
  matchability_ = upload(w.matchability, "lighterglue: matchability");
  rotary_ = array(context, "lighterglue: rotary weights", w.position);
  for (const nn::LighterGlueWeights::Layer& L : w.layers) {
    Layer d;
    d.qkv = upload(L.qkv, "lighterglue: qkv");
    d.self_out = upload(L.self_out, "lighterglue: self output");
    d.self_ffn = upload(L.self_ffn);
    d.cross_qk = upload(L.cross_qk, "lighterglue: cross qk");
    d.cross_v = upload(L.cross_v, "lighterglue: cross v");
    d.cross_out = upload(L.cross_out, "lighterglue: cross output");
    d.cross_ffn = upload(L.cross_ffn);
    if (d.qkv.out != 3 * dim_ || d.self_ffn.expand.in != 2 * dim_ || d.cross_ffn.project.out != dim_)
      throw std::invalid_argument("LighterGlueNetwork: a layer without LighterGlue's shapes");
    layers_.push_back(std::move(d));
  }
}

LighterGlueNetwork::~LighterGlueNetwork() = default;

LighterGlueMatches LighterGlueNetwork::match(const std::vector<float>& kp0, const std::vector<float>& desc0,
                                             const std::vector<float>& kp1,
                                             const std::vector<float>& desc1) const {
  if (kp0.size() % 2 || kp1.size() % 2 || desc0.size() != kp0.size() / 2 * descriptor_width_ ||
      desc1.size() != kp1.size() / 2 * descriptor_width_)
    throw std::invalid_argument("LighterGlueNetwork::match: [n][2] keypoints with [n][" +
                                std::to_string(descriptor_width_) + "] descriptors per image");
  const auto n0 = static_cast<uint32_t>(kp0.size() / 2), n1 = static_cast<uint32_t>(kp1.size() / 2);
  LighterGlueMatches out;
  if (!n0 || !n1) return out;
  const uint32_t n = n0 + n1, d = dim_;
  engine::Context& c = *context_;
  std::vector<float> keypoints(kp0), descriptors(desc0);
  keypoints.insert(keypoints.end(), kp1.begin(), kp1.end());
  descriptors.insert(descriptors.end(), desc1.begin(), desc1.end());
  const auto points = array(c, "lighterglue: keypoints", keypoints);
  const auto input = array(c, "lighterglue: descriptors", descriptors);
  Array x(c, "lighterglue: state", size_t{n} * d), x_next(c, "lighterglue: state", size_t{n} * d);
  Array wide(c, "lighterglue: qkv", size_t{n} * 3 * d), split(c, "lighterglue: q k v", size_t{n} * 3 * d);
  Array message(c, "lighterglue: message", size_t{n} * d),
      projected(c, "lighterglue: message", size_t{n} * d);
  Array hidden(c, "lighterglue: feed-forward", size_t{n} * 2 * d);
  const uint32_t largest = std::max(n0, n1);
  // The similarities' and the probabilities' rows padded to four floats, so that the softmax and the
  // products read them as four-float texels.
  Array attention(c, "lighterglue: attention", size_t{largest} * padded_row(largest)),
      probabilities(c, "lighterglue: attention probabilities", size_t{largest} * padded_row(largest));
  Array z(c, "lighterglue: matchability", n),
      lse(c, "lighterglue: log-sum-exps and log-sigmoids", assignment_scratch_floats(n0, n1));
  Array scores(c, "lighterglue: scores", size_t{n0} * n1);
  engine::Sequence s(c);
  const auto linear = [&](const Array& a, uint32_t a_cols, const Array* b, const Linear& l,
                          const Array* residual, const Array& y) {
    ops_.linear(s, a.buffer(), a_cols, b ? &b->buffer() : nullptr, b ? l.in - a_cols : 0, l.weight->buffer(),
                l.bias ? &l.bias->buffer() : nullptr, residual ? &residual->buffer() : nullptr, y.buffer(), n,
                l.out);
  };
  const float scale = 1.0f / std::sqrt(static_cast<float>(d));
  const uint32_t first[2] = {0, n0}, count[2] = {n0, n1};
  linear(*input, descriptor_width_, nullptr, input_, nullptr, x);
  Array* state = &x;
  Array* next = &x_next;
  // state = state + ffn([state, projected message]), through `next`.
  const auto feed_forward = [&](const FeedForward& f) {
    linear(*state, d, &projected, f.expand, nullptr, hidden);
    ops_.layer_norm_gelu(s, hidden.buffer(), f.scale->buffer(), f.shift->buffer(), n, 2 * d, f.epsilon);
    linear(hidden, 2 * d, nullptr, f.project, state, *next);
    std::swap(state, next);
  };
  for (const Layer& L : layers_) {
    linear(*state, d, nullptr, L.qkv, nullptr, wide);
    ops_.split_rotary(s, wide.buffer(), points->buffer(), rotary_->buffer(), split.buffer(), n, d);
    for (int i = 0; i < 2; ++i) {  // each image attends to itself
      const RowBlock q{&split.buffer(), first[i], count[i], d}, k{&split.buffer(), n + first[i], count[i], d},
          v{&split.buffer(), 2 * n + first[i], count[i], d};
      const uint32_t stride = padded_row(count[i]);
      ops_.multiply_transposed(s, q, k, attention.buffer(), scale, stride);
      ops_.softmax_rows(s, attention.buffer(), probabilities.buffer(), count[i], count[i], stride, stride);
      ops_.multiply(s, RowBlock{&probabilities.buffer(), 0, count[i], count[i], padded_row(count[i])}, v,
                    message.buffer(), first[i]);
    }
    linear(message, d, nullptr, L.self_out, nullptr, projected);
    feed_forward(L.self_ffn);
    linear(*state, d, nullptr, L.cross_qk, nullptr, wide);  // qk in the first n d floats of `wide`
    linear(*state, d, nullptr, L.cross_v, nullptr, split);  // v in the first n d floats of `split`
    // Each image attends to the other through one similarity [n0][n1]: the second image's attention is the
    // softmax of its columns (the same floats as a product of its own, whose terms commute).
    ops_.multiply_transposed(s, RowBlock{&wide.buffer(), 0, n0, d}, RowBlock{&wide.buffer(), n0, n1, d},
                             attention.buffer(), scale, padded_row(n1));
    ops_.softmax_rows(s, attention.buffer(), probabilities.buffer(), n0, n1, padded_row(n1), padded_row(n1));
    ops_.multiply(s, RowBlock{&probabilities.buffer(), 0, n0, n1, padded_row(n1)},
                  RowBlock{&split.buffer(), n0, n1, d}, message.buffer(), 0);
    ops_.softmax_columns(s, attention.buffer(), probabilities.buffer(), n0, n1, padded_row(n0),
                         padded_row(n1));
    ops_.multiply(s, RowBlock{&probabilities.buffer(), 0, n1, n0, padded_row(n0)},
                  RowBlock{&split.buffer(), 0, n0, d}, message.buffer(), n0);
    linear(message, d, nullptr, L.cross_out, nullptr, projected);
    feed_forward(L.cross_ffn);
  }
  linear(*state, d, nullptr, final_, nullptr, message);
  // sim = d0 d1^T / sqrt(dim) (the graph divides each side by dim^(1/4)).
  ops_.multiply_transposed(s, RowBlock{&message.buffer(), 0, n0, d}, RowBlock{&message.buffer(), n0, n1, d},
                           attention.buffer(), scale);
  linear(*state, d, nullptr, matchability_, nullptr, z);
  ops_.assignment(s, attention.buffer(), z.buffer(), lse.buffer(), scores.buffer(), n0, n1);
  s.submit_and_wait();
  out.kernel_times = s.profile();
  out.scores = scores.download();
  nn::Matrix m(n0, n1);
  for (size_t i = 0; i < out.scores.size(); ++i) m.values[i] = out.scores[i];
  nn::mutual_best(m, out.matches, out.match_scores);
  return out;
}

}  // namespace litgs::kernels
