// A render request of the service, parsed and checked before it reaches the device (docs/serve.md has the
// schema). Every problem is a RequestError (400) naming the field.
#pragma once

#include <cstdint>
#include <optional>
#include <string>
#include <utility>
#include <vector>

#include "io/palette.h"
#include "kernels/splat/splat_types.h"
#include "tools/serve/request_error.h"

namespace litgs::serve {

enum class Encoding { kPng8, kPng16, kFloat32 };

struct OutputRequest {
  bool wanted = false;
  Encoding encoding = Encoding::kPng8;
  double scale = 1.0;                  // PNG value per unit (image: full scale; depth: per metre)
  std::optional<io::Palette> palette;  // an 8-bit RGB PNG of the values over [lo, hi]
  double lo = 0, hi = 1;
};

struct RenderRequest {
  std::string model = "default";
  kernels::SplatCamera camera;  // sh_degree is set once the model is known (sh_degree below)
  int sh_degree = -1;           // -1: the model's
  OutputRequest image, depth, alpha;
  bool bundle = false;  // JSON bundle even for one output (always for several)
  size_t output_count() const { return size_t{image.wanted} + depth.wanted + alpha.wanted; }
};

struct RequestLimits {
  uint64_t max_pixels = 4'194'304;
};

// POST /render's JSON body.
RenderRequest parse_render_json(const std::string& body, const RequestLimits& limits);
// GET /render's query parameters (name, value), in the order given.
RenderRequest parse_render_query(const std::vector<std::pair<std::string, std::string>>& params,
                                 const RequestLimits& limits);

}  // namespace litgs::serve
