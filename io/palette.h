// False-colour palettes for one-channel (thermal) values: a value range [lo, hi] mapped onto 256 colours.
// One table per palette, shared by the render service (PNG outputs, the viewer's legend) and `export splat`.
#pragma once

#include <array>
#include <cstdint>
#include <string>
#include <vector>

namespace litgs::io {

enum class Palette { kGray, kIronbow };

// "gray" or "ironbow"; std::invalid_argument naming the value and the choices otherwise.
Palette parse_palette(const std::string& name);
std::vector<std::string> palette_names();

using Rgb = std::array<uint8_t, 3>;
// The 256 colours of a palette, index 0 for lo and 255 for hi.
const std::array<Rgb, 256>& palette_table(Palette palette);

// The palette index of `value` in [lo, hi] (clamped; non-finite values: 0). Needs hi > lo.
uint8_t palette_index(double value, double lo, double hi);

}  // namespace litgs::io
