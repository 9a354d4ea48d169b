// Images as the engine reads and writes them: 8- or 16-bit, 1 to 4 channels, from PNG (libpng) or TIFF
// (libtiff, which reads radiometric frames that lack the PhotometricInterpretation tag).
#pragma once

#include <cstdint>
#include <filesystem>
#include <vector>

namespace litgs::io {

// Pixels are stored as uint16_t whatever the bit depth: an 8-bit image holds 0..255, a 16-bit one 0..65535
// (raw radiometric counts are kept exactly; no scaling on read or write). Row-major, channels interleaved:
// pixel (x, y) channel c is data[(y * width + x) * channels + c].
struct Image {
  int width = 0;
  int height = 0;
  int channels = 1;            // 1 gray, 2 gray+alpha, 3 RGB, 4 RGBA
  int bit_depth = 8;           // 8 or 16
  std::vector<uint16_t> data;  // [height, width, channels]

  uint16_t at(int x, int y, int c = 0) const {
    return data[(static_cast<size_t>(y) * width + x) * channels + c];
  }
  // Throws std::invalid_argument naming the bad field (sizes, depth, data length, values above the depth).
  void check() const;
};

// What a file's header says, without decoding pixels (the scene reader checks every frame with this).
struct ImageInfo {
  int width = 0, height = 0, channels = 0, bit_depth = 0;
};

// By extension: .png, or .tif/.tiff. IoError naming the file on a missing, truncated or corrupt file, an
// unsupported layout (bit depth other than 8/16 after expansion, float or tiled TIFF, planar TIFF), or an
// unknown extension.
Image read_image(const std::filesystem::path& path);
ImageInfo read_image_info(const std::filesystem::path& path);

// By extension (.png, .tif/.tiff), atomically. PNG: 8/16-bit; TIFF: 8/16-bit, deflate-compressed.
void write_image(const std::filesystem::path& path, const Image& image);

// One channel of a frame read for a thermal scene: a 1-channel image as it is; gray+alpha as its gray
// channel; RGB(A) whose colour channels are equal at every pixel (an 8-bit thermal frame saved as colour)
// as its first channel. IoError naming `path` and the first pixel where the colour channels differ.
Image single_channel(Image image, const std::filesystem::path& path);

// The format-specific entry points behind the above.
Image read_png(const std::filesystem::path& path);
ImageInfo read_png_info(const std::filesystem::path& path);
void write_png(const std::filesystem::path& path, const Image& image);
// The bytes write_png would write (same libpng settings), in memory (for the render service).
std::vector<uint8_t> encode_png(const Image& image);
Image read_tiff(const std::filesystem::path& path);
ImageInfo read_tiff_info(const std::filesystem::path& path);
void write_tiff(const std::filesystem::path& path, const Image& image);
// JPEG (read only): 8-bit gray or RGB, through libjpeg.
Image read_jpeg(const std::filesystem::path& path);
ImageInfo read_jpeg_info(const std::filesystem::path& path);

}  // namespace litgs::io
