// libFuzzer target: host::read_checkpoint (training checkpoints; compiled from host/train/checkpoint.cc
// without the GPU stack).
#include "host/train/checkpoint.h"
#include "tests/fuzz/fuzz_util.h"

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  const auto path = litgs::fuzz::write_temp("run.ckpt", data, size);
  return litgs::fuzz::expect_only_io_error([&] { litgs::host::read_checkpoint(path); });
}
