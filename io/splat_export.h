// The 32-byte-per-Gaussian .splat layout that web splat viewers load: position (3 float32), linear scale
// (3 float32), colour RGBA (4 uint8: colour from the degree-0 SH term, alpha = sigmoid(opacity)), rotation
// (4 uint8: the normalized quaternion w x y z mapped from [-1, 1] to [0, 255] as q * 128 + 128), little
// endian, most visible Gaussians first (exp(sum of log-scales) * opacity, descending). Higher SH degrees are
// dropped: the format has none.
#pragma once

#include <cstdint>
#include <filesystem>
#include <optional>
#include <vector>

#include "io/palette.h"
#include "kernels/splat/splat_types.h"

namespace litgs::io {

struct SplatColouring {
  // One-channel models: gray (value * 255) unless a palette maps [lo, hi]; three-channel models take their
  // colour and refuse a palette (std::invalid_argument).
  std::optional<Palette> palette;
  double lo = 0, hi = 1;
};

// The file's bytes. std::invalid_argument for a bad model (GaussianModel::check), a palette on an RGB model,
// hi <= lo or a non-finite range.
std::vector<uint8_t> encode_splat(const kernels::GaussianModel& model, const SplatColouring& colouring = {});
// Writes them atomically; returns the number of Gaussians written.
size_t write_splat(const std::filesystem::path& path, const kernels::GaussianModel& model,
                   const SplatColouring& colouring = {});

}  // namespace litgs::io
