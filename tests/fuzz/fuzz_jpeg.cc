// libFuzzer target: io::read_jpeg_info and io::read_jpeg (DJI radiometric JPEGs).
#include "io/image.h"
#include "tests/fuzz/fuzz_util.h"

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  const auto path = litgs::fuzz::write_temp("image.jpg", data, size);
  return litgs::fuzz::expect_only_io_error([&] {
    litgs::io::read_jpeg_info(path);
    litgs::io::read_jpeg(path);
  });
}
