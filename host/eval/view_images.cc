#include "host/eval/view_images.h"

#include <algorithm>
#include <cmath>
#include <limits>

namespace litgs::host {
namespace {

using Stops = std::vector<std::array<double, 3>>;

const Stops& stops(Palette p) {
  static const Stops thermal = {{0, 0, 0},        {0.35, 0.0, 0.55}, {0.8, 0.1, 0.25},
                                {0.98, 0.5, 0.0}, {1.0, 0.85, 0.1},  {1, 1, 1}};
  static const Stops error = {{0, 0, 0}, {0.55, 0.0, 0.0}, {1.0, 0.55, 0.0}, {1, 1, 1}};
  static const Stops depth = {{0.1, 0.05, 0.4}, {0.0, 0.45, 0.55}, {0.3, 0.75, 0.3}, {1.0, 0.95, 0.2}};
  static const Stops uncovered = {{0, 0, 0}, {0.0, 0.1, 0.6}, {0.0, 0.75, 1.0}, {1, 1, 1}};
  switch (p) {
    case Palette::kThermal:
      return thermal;
    case Palette::kError:
      return error;
    case Palette::kErrorUncovered:
      return uncovered;
    default:
      return depth;
  }
}

}  // namespace

std::array<uint8_t, 3> palette_colour(Palette palette, double value) {
  const Stops& s = stops(palette);
  const double v =
      std::clamp(std::isfinite(value) ? value : 0.0, 0.0, 1.0) * static_cast<double>(s.size() - 1);
  const size_t k = std::min(static_cast<size_t>(v), s.size() - 2);
  const double f = v - static_cast<double>(k);
  std::array<uint8_t, 3> rgb{};
  for (int c = 0; c < 3; ++c)
    rgb[c] = static_cast<uint8_t>(std::lround(255.0 * ((1 - f) * s[k][c] + f * s[k + 1][c])));
  return rgb;
}

io::Image gray_image(std::span<const float> values, uint32_t width, uint32_t height) {
  io::Image img;
  img.width = static_cast<int>(width);
  img.height = static_cast<int>(height);
  img.channels = 1;
  img.bit_depth = 8;
  img.data.resize(values.size());
  for (size_t p = 0; p < values.size(); ++p) {
    const double v = std::isfinite(values[p]) ? values[p] : 0.0;
    img.data[p] = static_cast<uint16_t>(std::lround(255.0 * std::clamp(v, 0.0, 1.0)));
  }
  return img;
}

io::Image colour_image(std::span<const float> values, uint32_t width, uint32_t height, Palette palette,
                       double low, double high, std::span<const float> mask) {
  io::Image img;
  img.width = static_cast<int>(width);
  img.height = static_cast<int>(height);
  img.channels = 3;
  img.bit_depth = 8;
  img.data.assign(values.size() * 3, 0);
  const double range = high > low ? high - low : 1.0;
  for (size_t p = 0; p < values.size(); ++p) {
    if (!mask.empty() && mask[p] < 0.5f) continue;
    const auto rgb = palette_colour(palette, (values[p] - low) / range);
    for (int c = 0; c < 3; ++c) img.data[3 * p + c] = rgb[c];
  }
  return img;
}

nlohmann::json write_view_images(const std::filesystem::path& dir, const ViewImages& v) {
  const std::string stem = std::filesystem::path(v.name).stem().string();
  std::vector<float> error(v.render.size());
  for (size_t p = 0; p < error.size(); ++p) error[p] = std::abs(v.render[p] - v.target[p]);
  double near = std::numeric_limits<double>::infinity(), far = 0;
  for (size_t p = 0; p < v.depth_m.size(); ++p)
    if (v.alpha[p] >= 0.5f && std::isfinite(v.depth_m[p])) {
      near = std::min(near, double{v.depth_m[p]});
      far = std::max(far, double{v.depth_m[p]});
    }
  if (!(far >= near)) near = far = 0;
  nlohmann::json j = {{"name", v.name},
                      {"render", stem + ".render.png"},
                      {"target", stem + ".target.png"},
                      {"error", stem + ".error.png"},
                      {"false_colour", stem + ".false.png"},
                      {"depth", stem + ".depth.png"},
                      {"depth_min_m", near},
                      {"depth_max_m", far}};
  io::write_image(dir / j["render"].get<std::string>(), gray_image(v.render, v.width, v.height));
  io::write_image(dir / j["target"].get<std::string>(), gray_image(v.target, v.width, v.height));
  io::Image error_map = colour_image(error, v.width, v.height, Palette::kError, 0.0, kErrorFullScale);
  bool uncovered_shown = false;
  for (size_t p = 0; p < v.covisible.size() && p < error.size(); ++p)
    if (!v.covisible[p]) {
      const auto rgb = palette_colour(Palette::kErrorUncovered, error[p] / kErrorFullScale);
      for (int c = 0; c < 3; ++c) error_map.data[3 * p + c] = rgb[c];
      uncovered_shown = true;
    }
  j["error_uncovered_shown"] = uncovered_shown;
  io::write_image(dir / j["error"].get<std::string>(), error_map);
  io::write_image(dir / j["false_colour"].get<std::string>(),
                  colour_image(v.render, v.width, v.height, Palette::kThermal, 0.0, 1.0));
  io::write_image(dir / j["depth"].get<std::string>(),
                  colour_image(v.depth_m, v.width, v.height, Palette::kDepth, near, far, v.alpha));
  return j;
}

}  // namespace litgs::host
