// The held-out views as pictures for the report: the render and the real frame (8-bit gray), the absolute
// error and the render in false colour, and the rendered depth in colour. Written as PNG.
#pragma once

#include <array>
#include <cstdint>
#include <filesystem>
#include <nlohmann/json.hpp>
#include <span>
#include <vector>

#include "host/eval/evaluate_model.h"
#include "io/image.h"

namespace litgs::host {

// The colour ramps, each as a piecewise-linear curve through a few RGB stops at equal spacing.
enum class Palette {
  kThermal,         // black, violet, red, orange, yellow, white: the "iron" look of thermal viewers
  kError,           // black, dark red, orange, white: 0 error black
  kDepth,           // dark blue, teal, green, yellow: near to far
  kErrorUncovered,  // black, dark blue, cyan, white: the error where no training view saw the surface
};
std::array<uint8_t, 3> palette_colour(Palette palette, double value);  // value in [0, 1] (clamped)

// 8-bit gray of values in [0, 1] (clamped), or RGB through `palette` of (v - low) / (high - low); pixels
// where `mask` is given and below 0.5 are black.
io::Image gray_image(std::span<const float> values, uint32_t width, uint32_t height);
io::Image colour_image(std::span<const float> values, uint32_t width, uint32_t height, Palette palette,
                       double low, double high, std::span<const float> mask = {});

// The absolute error's full scale in the error maps: 0.25 of the [0, 1] intensity range is white.
inline constexpr double kErrorFullScale = 0.25;

// Writes DIR/<stem>.{render,target,error,false,depth}.png for the view (stem: the frame name without its
// extension) and returns {"name", "render", "target", "error", "false_colour", "depth", "depth_min_m",
// "depth_max_m", "error_uncovered_shown"} (file names relative to DIR; depth range over pixels with alpha >=
// 0.5). Where the view has a co-visibility mask, the error map draws the pixels no training view saw in the
// kErrorUncovered ramp (error_uncovered_shown: true when there are any).
nlohmann::json write_view_images(const std::filesystem::path& dir, const ViewImages& view);

}  // namespace litgs::host
