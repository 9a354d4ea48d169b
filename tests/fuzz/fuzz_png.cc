// libFuzzer target: io::read_png_info and io::read_png.
#include "io/image.h"
#include "tests/fuzz/fuzz_util.h"

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  const auto path = litgs::fuzz::write_temp("image.png", data, size);
  return litgs::fuzz::expect_only_io_error([&] {
    litgs::io::read_png_info(path);
    litgs::io::read_png(path);
  });
}
