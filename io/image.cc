#include "io/image.h"

#include <algorithm>
#include <stdexcept>
#include <string>

#include "io/error.h"

namespace litgs::io {
namespace {

enum class Kind { kPng, kTiff };

Kind kind_of(const std::filesystem::path& path) {
  std::string ext = path.extension().string();
  std::transform(ext.begin(), ext.end(), ext.begin(), [](unsigned char c) { return std::tolower(c); });
  if (ext == ".png") return Kind::kPng;
  if (ext == ".tif" || ext == ".tiff") return Kind::kTiff;
  fail(path, 0, "unknown image extension '" + ext + "' (expected .png, .tif or .tiff)");
}

}  // namespace

void Image::check() const {
  const auto bad = [](const std::string& what) { throw std::invalid_argument("Image: " + what); };
  if (width <= 0 || height <= 0)
    bad("width and height must be positive, got " + std::to_string(width) + "x" + std::to_string(height));
  if (channels < 1 || channels > 4) bad("channels must be 1..4, got " + std::to_string(channels));
  if (bit_depth != 8 && bit_depth != 16) bad("bit_depth must be 8 or 16, got " + std::to_string(bit_depth));
  const size_t n = static_cast<size_t>(width) * height * channels;
  if (data.size() != n)
    bad("data has " + std::to_string(data.size()) + " values, expected " + std::to_string(n));
  if (bit_depth == 8)
    for (uint16_t v : data)
      if (v > 255) bad("8-bit image holds the value " + std::to_string(v));
}

Image read_image(const std::filesystem::path& path) {
  return kind_of(path) == Kind::kPng ? read_png(path) : read_tiff(path);
}

ImageInfo read_image_info(const std::filesystem::path& path) {
  return kind_of(path) == Kind::kPng ? read_png_info(path) : read_tiff_info(path);
}

void write_image(const std::filesystem::path& path, const Image& image) {
  if (kind_of(path) == Kind::kPng)
    write_png(path, image);
  else
    write_tiff(path, image);
}

}  // namespace litgs::io
