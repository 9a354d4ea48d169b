// TIFF through libtiff directly. libtiff reports errors through a process-wide handler: ours keeps the last
// message per thread so the IoError can quote it. Radiometric frames without a PhotometricInterpretation tag
// (Workswell WIRIS) read fine: we take the layout from BitsPerSample / SamplesPerPixel / SampleFormat.
#include <tiffio.h>

#include <cstdarg>
#include <cstdio>
#include <cstring>
#include <mutex>
#include <string>

#include "io/atomic_file.h"
#include "io/error.h"
#include "io/image.h"

namespace litgs::io {
namespace {

thread_local std::string t_last_error;

void on_error(const char* module, const char* fmt, va_list args) {
  char buf[512];
  std::vsnprintf(buf, sizeof(buf), fmt, args);
  t_last_error = (module ? std::string(module) + ": " : std::string()) + buf;
}

void on_warning(const char*, const char*, va_list) {}  // e.g. unknown private tags of camera vendors

void install_handlers() {
  static std::once_flag once;
  std::call_once(once, [] {
    TIFFSetErrorHandler(on_error);
    TIFFSetWarningHandler(on_warning);
  });
}

// Closes the TIFF on every path out of a scope.
struct TiffCloser {
  TIFF* tif;
  ~TiffCloser() {
    if (tif) TIFFClose(tif);
  }
};

TIFF* open_for_read(const std::filesystem::path& path) {
  install_handlers();
  if (!std::filesystem::exists(path)) fail(path, 0, "file does not exist");
  t_last_error.clear();
  TIFF* tif = TIFFOpen(path.c_str(), "r");
  if (!tif) fail(path, 0, "not a readable TIFF: libtiff: " + t_last_error);
  return tif;
}

ImageInfo layout(const std::filesystem::path& path, TIFF* tif) {
  uint32_t width = 0, height = 0;
  uint16_t bits = 0, samples = 0, format = SAMPLEFORMAT_UINT, planar = PLANARCONFIG_CONTIG;
  if (!TIFFGetField(tif, TIFFTAG_IMAGEWIDTH, &width) || !TIFFGetField(tif, TIFFTAG_IMAGELENGTH, &height))
    fail(path, 0, "no ImageWidth/ImageLength tags");
  TIFFGetFieldDefaulted(tif, TIFFTAG_BITSPERSAMPLE, &bits);
  TIFFGetFieldDefaulted(tif, TIFFTAG_SAMPLESPERPIXEL, &samples);
  TIFFGetFieldDefaulted(tif, TIFFTAG_SAMPLEFORMAT, &format);
  TIFFGetFieldDefaulted(tif, TIFFTAG_PLANARCONFIG, &planar);
  if (bits != 8 && bits != 16)
    fail(path, 0, "unsupported BitsPerSample " + std::to_string(bits) + " (8 or 16)");
  if (format != SAMPLEFORMAT_UINT)
    fail(path, 0, "unsupported SampleFormat " + std::to_string(format) + " (uint)");
  if (samples < 1 || samples > 4) fail(path, 0, "unsupported SamplesPerPixel " + std::to_string(samples));
  if (planar != PLANARCONFIG_CONTIG && samples > 1) fail(path, 0, "planar (separate) TIFF is not supported");
  if (TIFFIsTiled(tif)) fail(path, 0, "tiled TIFF is not supported");
  if (width == 0 || height == 0 || width > (1u << 16) || height > (1u << 16))
    fail(path, 0, "implausible size " + std::to_string(width) + "x" + std::to_string(height));
  return {static_cast<int>(width), static_cast<int>(height), samples, bits};
}

// Refuses a file whose strips cannot hold the image it declares, before the image is allocated (a 214-byte
// file declaring 9477x65277 pixels once asked for 3.7 GB): uncompressed strips hold their bytes, compressed
// ones expand at most 4096-fold (LZW's longest code string; deflate's limit is about 1032). The strips hold
// no more than the file does, whatever StripByteCounts claims (a 200-byte file claiming a 1.1 MB strip once
// passed the check and asked for 1.26 GB).
void check_stored_bytes(const std::filesystem::path& path, TIFF* tif, uint64_t decoded_bytes) {
  const uint64_t* counts = nullptr;
  if (!TIFFGetField(tif, TIFFTAG_STRIPBYTECOUNTS, &counts) || counts == nullptr)
    fail(path, 0, "no StripByteCounts tag");
  uint64_t stored = 0;
  for (uint32_t s = 0; s < TIFFNumberOfStrips(tif); ++s) stored += counts[s];
  std::error_code error;
  const uintmax_t file_bytes = std::filesystem::file_size(path, error);
  const bool beyond_the_file = !error && stored > file_bytes;
  if (beyond_the_file) stored = file_bytes;
  uint16_t compression = COMPRESSION_NONE;
  TIFFGetFieldDefaulted(tif, TIFFTAG_COMPRESSION, &compression);
  const uint64_t expansion = compression == COMPRESSION_NONE ? 1 : 4096;
  if (decoded_bytes / expansion > stored)
    fail(path, 0,
         "TIFF declares " + std::to_string(decoded_bytes) + " bytes of pixels but its strips hold " +
             std::to_string(stored) + " bytes" + (beyond_the_file ? ", the whole file (truncated?)" : "") +
             (expansion > 1 ? " (compressed at most 4096-fold)" : ""));
}

}  // namespace

ImageInfo read_tiff_info(const std::filesystem::path& path) {
  TiffCloser tif{open_for_read(path)};
  return layout(path, tif.tif);
}

Image read_tiff(const std::filesystem::path& path) {
  TiffCloser tif{open_for_read(path)};
  const ImageInfo info = layout(path, tif.tif);
  Image image;
  image.width = info.width;
  image.height = info.height;
  image.channels = info.channels;
  image.bit_depth = info.bit_depth;
  const size_t row_values = static_cast<size_t>(info.width) * info.channels;
  const tmsize_t scanline = TIFFScanlineSize(tif.tif);
  if (scanline < static_cast<tmsize_t>(row_values * (info.bit_depth / 8)))
    fail(path, 0, "scanline size " + std::to_string(scanline) + " is smaller than the image row");
  check_stored_bytes(path, tif.tif, static_cast<uint64_t>(scanline) * static_cast<uint64_t>(info.height));
  std::vector<unsigned char> row(static_cast<size_t>(scanline));
  image.data.resize(row_values * info.height);
  for (int y = 0; y < info.height; ++y) {
    t_last_error.clear();
    if (TIFFReadScanline(tif.tif, row.data(), static_cast<uint32_t>(y), 0) < 0)
      fail(path, 0, "corrupt or truncated TIFF at row " + std::to_string(y) + ": libtiff: " + t_last_error);
    uint16_t* out = image.data.data() + static_cast<size_t>(y) * row_values;
    if (info.bit_depth == 8) {
      for (size_t i = 0; i < row_values; ++i) out[i] = row[i];
    } else {
      std::memcpy(out, row.data(), row_values * 2);  // libtiff returns host byte order
    }
  }
  return image;
}

void write_tiff(const std::filesystem::path& path, const Image& image) {
  image.check();
  install_handlers();
  AtomicFile file(path);
  {
    t_last_error.clear();
    TiffCloser tif{TIFFOpen(file.temp_path().c_str(), "w")};
    if (!tif.tif) fail(path, 0, "cannot open the temporary file for writing: libtiff: " + t_last_error);
    TIFF* t = tif.tif;
    TIFFSetField(t, TIFFTAG_IMAGEWIDTH, static_cast<uint32_t>(image.width));
    TIFFSetField(t, TIFFTAG_IMAGELENGTH, static_cast<uint32_t>(image.height));
    TIFFSetField(t, TIFFTAG_BITSPERSAMPLE, static_cast<uint16_t>(image.bit_depth));
    TIFFSetField(t, TIFFTAG_SAMPLESPERPIXEL, static_cast<uint16_t>(image.channels));
    TIFFSetField(t, TIFFTAG_SAMPLEFORMAT, static_cast<uint16_t>(SAMPLEFORMAT_UINT));
    TIFFSetField(t, TIFFTAG_PLANARCONFIG, static_cast<uint16_t>(PLANARCONFIG_CONTIG));
    TIFFSetField(t, TIFFTAG_PHOTOMETRIC,
                 static_cast<uint16_t>(image.channels >= 3 ? PHOTOMETRIC_RGB : PHOTOMETRIC_MINISBLACK));
    if (image.channels == 2 || image.channels == 4) {
      const uint16_t extra[1] = {EXTRASAMPLE_UNASSALPHA};
      TIFFSetField(t, TIFFTAG_EXTRASAMPLES, static_cast<uint16_t>(1), extra);
    }
    if (TIFFIsCODECConfigured(COMPRESSION_ADOBE_DEFLATE))
      TIFFSetField(t, TIFFTAG_COMPRESSION, static_cast<uint16_t>(COMPRESSION_ADOBE_DEFLATE));
    TIFFSetField(t, TIFFTAG_ROWSPERSTRIP, TIFFDefaultStripSize(t, 0));
    const size_t row_values = static_cast<size_t>(image.width) * image.channels;
    std::vector<unsigned char> row(row_values * (image.bit_depth / 8));
    for (int y = 0; y < image.height; ++y) {
      const uint16_t* in = image.data.data() + static_cast<size_t>(y) * row_values;
      if (image.bit_depth == 8) {
        for (size_t i = 0; i < row_values; ++i) row[i] = static_cast<unsigned char>(in[i]);
      } else {
        std::memcpy(row.data(), in, row.size());
      }
      if (TIFFWriteScanline(t, row.data(), static_cast<uint32_t>(y), 0) < 0)
        fail(path, 0, "write failed at row " + std::to_string(y) + ": libtiff: " + t_last_error);
    }
    if (!TIFFFlush(t)) fail(path, 0, "write failed (disk full?): libtiff: " + t_last_error);
  }
  file.commit();
}

}  // namespace litgs::io
