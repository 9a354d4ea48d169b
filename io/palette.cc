#include "io/palette.h"

#include <algorithm>
#include <cmath>
#include <stdexcept>

namespace litgs::io {
namespace {

struct Stop {
  double at;
  double r, g, b;
};

// Ironbow-like: black through deep blue-violet, magenta, orange and yellow to white, rising in lightness so
// that hotter reads brighter in gray too. Our own stops, not a copied table.
constexpr Stop kIronbowStops[] = {{0.00, 0, 0, 0},      {0.18, 40, 0, 120},  {0.38, 150, 0, 150},
                                  {0.58, 225, 60, 40},  {0.78, 250, 165, 0}, {0.92, 255, 230, 90},
                                  {1.00, 255, 255, 255}};

std::array<Rgb, 256> make_table(Palette p) {
  std::array<Rgb, 256> t{};
  for (int i = 0; i < 256; ++i) {
    const double x = i / 255.0;
    if (p == Palette::kGray) {
      t[i] = {uint8_t(i), uint8_t(i), uint8_t(i)};
      continue;
    }
    size_t k = 0;
    while (k + 2 < std::size(kIronbowStops) && x > kIronbowStops[k + 1].at) ++k;
    const Stop &a = kIronbowStops[k], &b = kIronbowStops[k + 1];
    const double f = std::clamp((x - a.at) / (b.at - a.at), 0.0, 1.0);
    auto mix = [f](double u, double v) { return uint8_t(std::lround(u + (v - u) * f)); };
    t[i] = {mix(a.r, b.r), mix(a.g, b.g), mix(a.b, b.b)};
  }
  return t;
}

}  // namespace

std::vector<std::string> palette_names() {
  return {"gray", "ironbow"};
}

Palette parse_palette(const std::string& name) {
  if (name == "gray") return Palette::kGray;
  if (name == "ironbow") return Palette::kIronbow;
  throw std::invalid_argument("unknown palette '" + name + "' (gray or ironbow)");
}

const std::array<Rgb, 256>& palette_table(Palette palette) {
  static const std::array<Rgb, 256> gray = make_table(Palette::kGray),
                                    ironbow = make_table(Palette::kIronbow);
  return palette == Palette::kGray ? gray : ironbow;
}

uint8_t palette_index(double value, double lo, double hi) {
  if (!std::isfinite(value)) return 0;
  return static_cast<uint8_t>(std::lround(std::clamp((value - lo) / (hi - lo), 0.0, 1.0) * 255.0));
}

}  // namespace litgs::io
