// libFuzzer target: io::read_scene_yaml (a scene directory's scene.yaml alone).
#include "io/scene_yaml.h"
#include "tests/fuzz/fuzz_util.h"

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  const auto path = litgs::fuzz::write_temp("scene.yaml", data, size);
  return litgs::fuzz::expect_only_io_error([&] { litgs::io::read_scene_yaml(path); });
}
