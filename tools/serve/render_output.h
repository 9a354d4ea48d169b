// A render's planes encoded as the request asked: one output alone as its own body (image/png, or raw
// little-endian float32 [C][H][W] as application/octet-stream), several (or "bundle": true) as one JSON
// object with each output base64-encoded (docs/serve.md).
#pragma once

#include <cstdint>
#include <string>
#include <utility>
#include <vector>

#include "tools/serve/render_request.h"

namespace litgs::serve {

struct RenderedView {
  uint32_t width = 0, height = 0, channels = 0;
  std::vector<float> image, depth, alpha;  // [C][H][W], [H][W], [H][W]
  uint64_t intersections = 0;
  double device_seconds = 0;
};

struct EncodedBody {
  std::string content_type;
  std::string body;
  std::vector<std::pair<std::string, std::string>> headers;
};

EncodedBody encode_outputs(const RenderRequest& request, const RenderedView& view);

std::string base64(const std::string& bytes);

}  // namespace litgs::serve
