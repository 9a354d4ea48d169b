#include "io/image.h"

#include <algorithm>
#include <stdexcept>
#include <string>

#include "io/error.h"

namespace litgs::io {
namespace {

enum class Kind { kPng, kTiff, kJpeg };

Kind kind_of(const std::filesystem::path& path) {
  std::string ext = path.extension().string();
  std::transform(ext.begin(), ext.end(), ext.begin(), [](unsigned char c) { return std::tolower(c); });
  if (ext == ".png") return Kind::kPng;
  if (ext == ".tif" || ext == ".tiff") return Kind::kTiff;
  if (ext == ".jpg" || ext == ".jpeg") return Kind::kJpeg;
  fail(path, 0, "unknown image extension '" + ext + "' (expected .png, .tif, .tiff, .jpg or .jpeg)");
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
  switch (kind_of(path)) {
    case Kind::kPng:
      return read_png(path);
    case Kind::kTiff:
      return read_tiff(path);
    default:
      return read_jpeg(path);
  }
}

ImageInfo read_image_info(const std::filesystem::path& path) {
  switch (kind_of(path)) {
    case Kind::kPng:
      return read_png_info(path);
    case Kind::kTiff:
      return read_tiff_info(path);
    default:
      return read_jpeg_info(path);
  }
}

void write_image(const std::filesystem::path& path, const Image& image) {
  switch (kind_of(path)) {
    case Kind::kPng:
      return write_png(path, image);
    case Kind::kTiff:
      return write_tiff(path, image);
    default:
      fail(path, 0, "writing JPEG is not supported (lossy): write .png or .tiff");
  }
}

Image single_channel(Image im, const std::filesystem::path& path) {
  if (im.channels == 1) return im;
  const int colour = im.channels >= 3 ? 3 : 1;  // gray+alpha: the gray channel; RGB(A): R = G = B
  Image out;
  out.width = im.width;
  out.height = im.height;
  out.bit_depth = im.bit_depth;
  out.channels = 1;
  out.data.resize(static_cast<size_t>(im.width) * im.height);
  for (size_t i = 0; i < out.data.size(); ++i) {
    const uint16_t* px = &im.data[i * static_cast<size_t>(im.channels)];
    for (int c = 1; c < colour; ++c)
      if (px[c] != px[0])
        fail(path, 0,
             "colour image (channel " + std::to_string(c) + " differs from channel 0 at pixel " +
                 std::to_string(i % static_cast<size_t>(im.width)) + ", " +
                 std::to_string(i / static_cast<size_t>(im.width)) + "): scene frames are single-channel");
    out.data[i] = px[0];
  }
  return out;
}

}  // namespace litgs::io
