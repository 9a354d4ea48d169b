#include "tools/serve/render_output.h"

#include <cstring>
#include <nlohmann/json.hpp>

#include "io/image.h"
#include "tools/render_view.h"

namespace litgs::serve {
namespace {

struct Encoded {
  std::string bytes;
  std::string format;  // png8 | png16 | png8-rgb | float32
  uint32_t channels = 1;
};

std::string png_bytes(const io::Image& image) {
  const std::vector<uint8_t> png = io::encode_png(image);
  return std::string(png.begin(), png.end());
}

// The planes as the output asks. PNG values come from tools::to_image, as `litgs-engine render` writes them.
Encoded encode(const OutputRequest& o, const std::vector<float>& planes, uint32_t w, uint32_t h, uint32_t c) {
  Encoded e;
  e.channels = c;
  if (o.palette) {
    const auto& table = io::palette_table(*o.palette);
    io::Image rgb;
    rgb.width = static_cast<int>(w);
    rgb.height = static_cast<int>(h);
    rgb.channels = 3;
    rgb.bit_depth = 8;
    rgb.data.resize(size_t{w} * h * 3);
    for (size_t p = 0; p < size_t{w} * h; ++p) {
      const io::Rgb colour = table[io::palette_index(planes[p], o.lo, o.hi)];
      for (int k = 0; k < 3; ++k) rgb.data[3 * p + k] = colour[k];
    }
    e.bytes = png_bytes(rgb);
    e.format = "png8-rgb";
    e.channels = 3;
  } else if (o.encoding == Encoding::kFloat32) {
    e.bytes.resize(planes.size() * sizeof(float));
    std::memcpy(e.bytes.data(), planes.data(), e.bytes.size());  // little-endian host
    e.format = "float32";
  } else {
    const int depth = o.encoding == Encoding::kPng16 ? 16 : 8;
    e.bytes = png_bytes(tools::to_image(planes, w, h, c, depth, o.scale));
    e.format = depth == 16 ? "png16" : "png8";
  }
  return e;
}

}  // namespace

std::string base64(const std::string& bytes) {
  static const char* kAlphabet = "ABCDEFGHIJKLMNOPQRSTUVWXYZabcdefghijklmnopqrstuvwxyz0123456789+/";
  std::string out;
  out.reserve((bytes.size() + 2) / 3 * 4);
  size_t i = 0;
  for (; i + 2 < bytes.size(); i += 3) {
    const uint32_t v =
        uint32_t(uint8_t(bytes[i])) << 16 | uint32_t(uint8_t(bytes[i + 1])) << 8 | uint8_t(bytes[i + 2]);
    for (int k = 3; k >= 0; --k) out += kAlphabet[(v >> (6 * k)) & 63];
  }
  if (i < bytes.size()) {
    const bool two = i + 1 < bytes.size();
    const uint32_t v = uint32_t(uint8_t(bytes[i])) << 16 | (two ? uint32_t(uint8_t(bytes[i + 1])) << 8 : 0);
    out += kAlphabet[(v >> 18) & 63];
    out += kAlphabet[(v >> 12) & 63];
    out += two ? kAlphabet[(v >> 6) & 63] : '=';
    out += '=';
  }
  return out;
}

EncodedBody encode_outputs(const RenderRequest& r, const RenderedView& v) {
  struct Named {
    const char* name;
    const OutputRequest& request;
    const std::vector<float>& planes;
    uint32_t channels;
  };
  const Named all[] = {{"image", r.image, v.image, v.channels},
                       {"depth", r.depth, v.depth, 1},
                       {"alpha", r.alpha, v.alpha, 1}};
  EncodedBody out;
  out.headers = {{"X-Width", std::to_string(v.width)},
                 {"X-Height", std::to_string(v.height)},
                 {"X-Intersections", std::to_string(v.intersections)}};
  if (r.output_count() == 1 && !r.bundle) {
    for (const Named& n : all) {
      if (!n.request.wanted) continue;
      Encoded e = encode(n.request, n.planes, v.width, v.height, n.channels);
      out.content_type = e.format == "float32" ? "application/octet-stream" : "image/png";
      out.headers.emplace_back("X-Output", n.name);
      out.headers.emplace_back("X-Format", e.format);
      out.headers.emplace_back("X-Channels", std::to_string(e.channels));
      out.body = std::move(e.bytes);
    }
    return out;
  }
  nlohmann::json j = {{"width", v.width}, {"height", v.height}, {"intersections", v.intersections}};
  for (const Named& n : all) {
    if (!n.request.wanted) continue;
    const Encoded e = encode(n.request, n.planes, v.width, v.height, n.channels);
    j["outputs"][n.name] = {{"format", e.format}, {"channels", e.channels}, {"base64", base64(e.bytes)}};
    if (n.request.palette) j["outputs"][n.name]["range"] = {n.request.lo, n.request.hi};
    if (n.name == std::string("depth") && e.format == "png16")
      j["outputs"][n.name]["scale"] = n.request.scale;
  }
  out.content_type = "application/json";
  out.body = j.dump();
  return out;
}

}  // namespace litgs::serve
