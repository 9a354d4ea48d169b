// JPEG reading through libjpeg (read only: frames such as the camera's own 8-bit mapping arrive as JPEG;
// the engine writes PNG or TIFF). libjpeg reports errors by longjmp: they become IoError naming the file.
#include <cstddef>
#include <cstdio>
// jpeglib.h uses size_t and FILE without including their headers: it comes after <cstddef> and <cstdio>.
#include <jpeglib.h>

#include <csetjmp>
#include <memory>
#include <string>

#include "io/error.h"
#include "io/image.h"

namespace litgs::io {
namespace {

struct ErrorManager {
  jpeg_error_mgr base;
  std::jmp_buf jump;
  char message[JMSG_LENGTH_MAX];
};

void on_error(j_common_ptr info) {
  auto* err = reinterpret_cast<ErrorManager*>(info->err);
  (*info->err->format_message)(info, err->message);
  std::longjmp(err->jump, 1);
}

// libjpeg only warns about a truncated or damaged stream (and fills the rest with gray): a frame with
// invented pixels must not reach training, so warnings are errors too.
void on_message(j_common_ptr info, int level) {
  if (level < 0) on_error(info);
}

// Decodes the header, and the pixels when `pixels` is given. Gray JPEGs give 1 channel, colour ones 3.
ImageInfo decode(const std::filesystem::path& path, Image* pixels) {
  std::unique_ptr<FILE, int (*)(FILE*)> file(std::fopen(path.c_str(), "rb"), &std::fclose);
  if (!file) fail(path, 0, "cannot open the JPEG file");
  jpeg_decompress_struct cinfo;
  ErrorManager err;
  cinfo.err = jpeg_std_error(&err.base);
  err.base.error_exit = on_error;
  err.base.emit_message = on_message;
  std::vector<uint8_t> row;
  ImageInfo info;
  if (setjmp(err.jump)) {
    jpeg_destroy_decompress(&cinfo);
    fail(path, 0, std::string("corrupt or truncated JPEG: ") + err.message);
  }
  jpeg_create_decompress(&cinfo);
  jpeg_stdio_src(&cinfo, file.get());
  jpeg_read_header(&cinfo, TRUE);
  info.width = static_cast<int>(cinfo.image_width);
  info.height = static_cast<int>(cinfo.image_height);
  info.channels = cinfo.num_components == 1 ? 1 : 3;
  info.bit_depth = 8;
  if (pixels) {
    cinfo.out_color_space = info.channels == 1 ? JCS_GRAYSCALE : JCS_RGB;
    jpeg_start_decompress(&cinfo);
    pixels->width = info.width;
    pixels->height = info.height;
    pixels->channels = info.channels;
    pixels->bit_depth = 8;
    pixels->data.resize(static_cast<size_t>(info.width) * info.height * info.channels);
    row.resize(static_cast<size_t>(info.width) * info.channels);
    while (cinfo.output_scanline < cinfo.output_height) {
      JSAMPROW rows[1] = {row.data()};
      const size_t y = cinfo.output_scanline;
      jpeg_read_scanlines(&cinfo, rows, 1);
      std::copy(row.begin(), row.end(), pixels->data.begin() + static_cast<long>(y * row.size()));
    }
    jpeg_finish_decompress(&cinfo);
  }
  jpeg_destroy_decompress(&cinfo);
  return info;
}

}  // namespace

Image read_jpeg(const std::filesystem::path& path) {
  Image img;
  decode(path, &img);
  return img;
}

ImageInfo read_jpeg_info(const std::filesystem::path& path) {
  return decode(path, nullptr);
}

}  // namespace litgs::io
