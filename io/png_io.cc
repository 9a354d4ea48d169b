// PNG through libpng's classic API. libpng reports errors by longjmp: every function that calls setjmp keeps
// only trivially destructible locals, and all C++ objects live in the caller's frame (a longjmp must never
// skip a destructor).
#include <png.h>

#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <stdexcept>
#include <string>

#include "io/atomic_file.h"
#include "io/error.h"
#include "io/image.h"

namespace litgs::io {
namespace {

struct PngError {
  char message[256] = {0};
};

void on_error(png_structp png, png_const_charp msg) {
  auto* e = static_cast<PngError*>(png_get_error_ptr(png));
  std::snprintf(e->message, sizeof(e->message), "%s", msg);
  png_longjmp(png, 1);
}

void on_warning(png_structp, png_const_charp) {}  // benign (e.g. unknown chunks, bad sRGB profiles)

struct PngRead {
  ImageInfo info;
  std::vector<unsigned char> pixels;  // rows of the decoded (expanded, host-endian) image
  std::vector<unsigned char*> rows;
};

// Returns false and fills err on failure; no non-trivial locals (see the file comment).
bool read_png_impl(std::FILE* fp, bool header_only, PngRead* out, PngError* err) {
  png_structp png = png_create_read_struct(PNG_LIBPNG_VER_STRING, err, on_error, on_warning);
  if (!png) {
    std::snprintf(err->message, sizeof(err->message), "libpng: cannot create a read struct");
    return false;
  }
  png_infop info = png_create_info_struct(png);
  if (!info) {
    png_destroy_read_struct(&png, nullptr, nullptr);
    std::snprintf(err->message, sizeof(err->message), "libpng: cannot create an info struct");
    return false;
  }
  if (setjmp(png_jmpbuf(png))) {
    png_destroy_read_struct(&png, &info, nullptr);
    return false;
  }
  png_init_io(png, fp);
  png_read_info(png, info);
  const int color_type = png_get_color_type(png, info);
  const int depth = png_get_bit_depth(png, info);
  if (color_type == PNG_COLOR_TYPE_PALETTE) png_set_palette_to_rgb(png);
  if (color_type == PNG_COLOR_TYPE_GRAY && depth < 8) png_set_expand_gray_1_2_4_to_8(png);
  if (png_get_valid(png, info, PNG_INFO_tRNS)) png_set_tRNS_to_alpha(png);
  if (depth == 16) png_set_swap(png);  // PNG is big-endian; the host is little-endian
  png_read_update_info(png, info);
  out->info.width = static_cast<int>(png_get_image_width(png, info));
  out->info.height = static_cast<int>(png_get_image_height(png, info));
  out->info.channels = png_get_channels(png, info);
  out->info.bit_depth = png_get_bit_depth(png, info);
  if (!header_only) {
    const size_t row_bytes = png_get_rowbytes(png, info);
    out->pixels.resize(row_bytes * static_cast<size_t>(out->info.height));
    out->rows.resize(static_cast<size_t>(out->info.height));
    for (size_t y = 0; y < out->rows.size(); ++y) out->rows[y] = out->pixels.data() + y * row_bytes;
    png_read_image(png, out->rows.data());
    png_read_end(png, nullptr);
  }
  png_destroy_read_struct(&png, &info, nullptr);
  return true;
}

bool write_png_impl(std::FILE* fp, const Image* image, unsigned char** rows, PngError* err) {
  png_structp png = png_create_write_struct(PNG_LIBPNG_VER_STRING, err, on_error, on_warning);
  if (!png) {
    std::snprintf(err->message, sizeof(err->message), "libpng: cannot create a write struct");
    return false;
  }
  png_infop info = png_create_info_struct(png);
  if (!info) {
    png_destroy_write_struct(&png, nullptr);
    std::snprintf(err->message, sizeof(err->message), "libpng: cannot create an info struct");
    return false;
  }
  if (setjmp(png_jmpbuf(png))) {
    png_destroy_write_struct(&png, &info);
    return false;
  }
  static const int color_types[5] = {0, PNG_COLOR_TYPE_GRAY, PNG_COLOR_TYPE_GRAY_ALPHA, PNG_COLOR_TYPE_RGB,
                                     PNG_COLOR_TYPE_RGB_ALPHA};
  png_init_io(png, fp);
  png_set_IHDR(png, info, static_cast<png_uint_32>(image->width), static_cast<png_uint_32>(image->height),
               image->bit_depth, color_types[image->channels], PNG_INTERLACE_NONE,
               PNG_COMPRESSION_TYPE_DEFAULT, PNG_FILTER_TYPE_DEFAULT);
  png_write_info(png, info);
  if (image->bit_depth == 16) png_set_swap(png);
  png_write_image(png, rows);
  png_write_end(png, nullptr);
  png_destroy_write_struct(&png, &info);
  return true;
}

PngRead read(const std::filesystem::path& path, bool header_only) {
  std::FILE* fp = std::fopen(path.c_str(), "rb");
  if (!fp) fail(path, 0, std::filesystem::exists(path) ? "cannot open for reading" : "file does not exist");
  unsigned char signature[8] = {0};
  const size_t got = std::fread(signature, 1, 8, fp);
  if (got != 8 || png_sig_cmp(signature, 0, 8) != 0) {
    std::fclose(fp);
    fail(path, 0, "not a PNG file (bad signature)");
  }
  std::rewind(fp);
  PngRead out;
  PngError err;
  const bool ok = read_png_impl(fp, header_only, &out, &err);
  std::fclose(fp);
  if (!ok) fail(path, 0, std::string("corrupt or truncated PNG: libpng: ") + err.message);
  if (out.info.bit_depth != 8 && out.info.bit_depth != 16)
    fail(path, 0, "unsupported bit depth " + std::to_string(out.info.bit_depth));
  return out;
}

}  // namespace

ImageInfo read_png_info(const std::filesystem::path& path) {
  return read(path, true).info;
}

Image read_png(const std::filesystem::path& path) {
  PngRead r = read(path, false);
  Image image;
  image.width = r.info.width;
  image.height = r.info.height;
  image.channels = r.info.channels;
  image.bit_depth = r.info.bit_depth;
  const size_t n = static_cast<size_t>(image.width) * image.height * image.channels;
  image.data.resize(n);
  if (image.bit_depth == 8) {
    for (size_t i = 0; i < n; ++i) image.data[i] = r.pixels[i];
  } else {
    std::memcpy(image.data.data(), r.pixels.data(), n * 2);
  }
  return image;
}

namespace {

// An image's pixels as PNG rows (big or little endian is libpng's business: png_set_swap).
struct PngRows {
  std::vector<unsigned char> bytes;
  std::vector<unsigned char*> rows;
};

PngRows png_rows(const Image& image) {
  image.check();
  const size_t row_values = static_cast<size_t>(image.width) * image.channels;
  const size_t row_bytes = row_values * (image.bit_depth / 8);
  PngRows r;
  r.bytes.resize(row_bytes * image.height);
  if (image.bit_depth == 8) {
    for (size_t i = 0; i < image.data.size(); ++i) r.bytes[i] = static_cast<unsigned char>(image.data[i]);
  } else {
    std::memcpy(r.bytes.data(), image.data.data(), r.bytes.size());
  }
  r.rows.resize(image.height);
  for (int y = 0; y < image.height; ++y) r.rows[y] = r.bytes.data() + y * row_bytes;
  return r;
}

}  // namespace

std::vector<uint8_t> encode_png(const Image& image) {
  PngRows rows = png_rows(image);
  char* buffer = nullptr;
  size_t size = 0;
  std::FILE* fp = open_memstream(&buffer, &size);  // POSIX 2008: a FILE* that writes into a growing buffer
  if (!fp) throw std::runtime_error("encode_png: open_memstream failed");
  PngError err;
  const bool ok = write_png_impl(fp, &image, rows.rows.data(), &err);
  std::fclose(fp);
  std::vector<uint8_t> out(buffer, buffer + (ok ? size : 0));
  std::free(buffer);
  if (!ok) throw std::runtime_error(std::string("encode_png: libpng: ") + err.message);
  return out;
}

void write_png(const std::filesystem::path& path, const Image& image) {
  PngRows rows = png_rows(image);
  AtomicFile file(path);
  std::FILE* fp = std::fopen(file.temp_path().c_str(), "wb");
  if (!fp) fail(path, 0, "cannot open the temporary file " + file.temp_path().string() + " for writing");
  PngError err;
  const bool ok = write_png_impl(fp, &image, rows.rows.data(), &err);
  const bool closed = std::fclose(fp) == 0;
  if (!ok) fail(path, 0, std::string("libpng: ") + err.message);
  if (!closed) fail(path, 0, "write failed (disk full?)");
  file.commit();
}

}  // namespace litgs::io
