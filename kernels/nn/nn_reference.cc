#include "kernels/nn/nn_reference.h"

#include <algorithm>
#include <cmath>
#include <stdexcept>
#include <string>

namespace litgs::kernels::nn {

FeatureMap conv2d(const FeatureMap& in, const ConvWeights& w) {
  if (static_cast<int>(w.in_channels) != in.channels ||
      w.weight.size() != size_t{w.out_channels} * w.in_channels * w.kernel * w.kernel ||
      w.bias.size() != w.out_channels || w.stride < 1 || !w.kernel)
    throw std::invalid_argument("conv2d: weights of " + std::to_string(w.in_channels) +
                                " input channels do not fit an input of " + std::to_string(in.channels));
  const int out_c = int(w.out_channels), k = int(w.kernel), stride = int(w.stride), pad = int(w.pad);
  const int out_h = (in.height + 2 * pad - k) / stride + 1, out_w = (in.width + 2 * pad - k) / stride + 1;
  FeatureMap out(out_c, out_h, out_w);
  for (int o = 0; o < out_c; ++o)
    for (int y = 0; y < out_h; ++y)
      for (int x = 0; x < out_w; ++x) {
        double sum = w.bias[o];
        for (int c = 0; c < in.channels; ++c)
          for (int ky = 0; ky < k; ++ky) {
            const int sy = y * stride - pad + ky;
            if (sy < 0 || sy >= in.height) continue;
            for (int kx = 0; kx < k; ++kx) {
              const int sx = x * stride - pad + kx;
              if (sx < 0 || sx >= in.width) continue;
              sum += double(w.weight[((size_t(o) * in.channels + c) * k + ky) * k + kx]) * in.at(c, sy, sx);
            }
          }
        out.at(o, y, x) = sum;
      }
  return out;
}

void relu(FeatureMap& m) {
  for (double& v : m.values) v = std::max(v, 0.0);
}

void sigmoid(FeatureMap& m) {
  for (double& v : m.values) v = 1.0 / (1.0 + std::exp(-v));
}

FeatureMap add(const FeatureMap& a, const FeatureMap& b) {
  if (a.channels != b.channels || a.height != b.height || a.width != b.width)
    throw std::invalid_argument("add: feature maps of different shapes");
  FeatureMap out = a;
  for (size_t i = 0; i < out.values.size(); ++i) out.values[i] += b.values[i];
  return out;
}

FeatureMap average_pool(const FeatureMap& in, int k, int stride) {
  FeatureMap out(in.channels, (in.height - k) / stride + 1, (in.width - k) / stride + 1);
  for (int c = 0; c < out.channels; ++c)
    for (int y = 0; y < out.height; ++y)
      for (int x = 0; x < out.width; ++x) {
        double sum = 0;
        for (int ky = 0; ky < k; ++ky)
          for (int kx = 0; kx < k; ++kx) sum += in.at(c, y * stride + ky, x * stride + kx);
        out.at(c, y, x) = sum / (k * k);
      }
  return out;
}

FeatureMap resize_bilinear(const FeatureMap& in, int height, int width) {
  FeatureMap out(in.channels, height, width);
  const auto source = [](int d, int in_size, int out_size, int& i0, int& i1, double& t) {
    double s = (d + 0.5) * in_size / out_size - 0.5;
    s = std::clamp(s, 0.0, double(in_size - 1));
    i0 = static_cast<int>(std::floor(s));
    i1 = std::min(i0 + 1, in_size - 1);
    t = s - i0;
  };
  for (int y = 0; y < height; ++y) {
    int y0, y1;
    double ty;
    source(y, in.height, height, y0, y1, ty);
    for (int x = 0; x < width; ++x) {
      int x0, x1;
      double tx;
      source(x, in.width, width, x0, x1, tx);
      for (int c = 0; c < in.channels; ++c)
        out.at(c, y, x) = (1 - ty) * ((1 - tx) * in.at(c, y0, x0) + tx * in.at(c, y0, x1)) +
                          ty * ((1 - tx) * in.at(c, y1, x0) + tx * in.at(c, y1, x1));
    }
  }
  return out;
}

FeatureMap unfold(const FeatureMap& in, int ws) {
  if (in.channels != 1 || in.height % ws || in.width % ws)
    throw std::invalid_argument("unfold: a one-channel image whose sides are multiples of " +
                                std::to_string(ws));
  FeatureMap out(ws * ws, in.height / ws, in.width / ws);
  for (int y = 0; y < out.height; ++y)
    for (int x = 0; x < out.width; ++x)
      for (int ky = 0; ky < ws; ++ky)
        for (int kx = 0; kx < ws; ++kx) out.at(ky * ws + kx, y, x) = in.at(0, y * ws + ky, x * ws + kx);
  return out;
}

}  // namespace litgs::kernels::nn
